#pragma once
// Wavefront OBJ text for inline test scenes.

#include <sstream>
#include <string>

namespace sandbox::testing {

// An axis-aligned box [x0, x0 + lx] x [y0, y0 + ly] x [z0, z0 + lz] as object
// `name`: 8 vertices, 6 outward quads (12 triangles). `first_vertex` is the OBJ
// index its vertices start at (1 for the first object in a file, 9 for the second).
inline std::string ObjBox(const std::string& name, double lx, double ly, double lz, double x0 = 0,
                          double y0 = 0, double z0 = 0, int first_vertex = 1) {
  const double x1 = x0 + lx, y1 = y0 + ly, z1 = z0 + lz;
  std::ostringstream out;
  out << "o " << name << "\n";
  for (const double z : {z0, z1}) {
    out << "v " << x0 << " " << y0 << " " << z << "\n"
        << "v " << x1 << " " << y0 << " " << z << "\n"
        << "v " << x1 << " " << y1 << " " << z << "\n"
        << "v " << x0 << " " << y1 << " " << z << "\n";
  }
  const int faces[6][4] = {{1, 4, 3, 2}, {5, 6, 7, 8}, {1, 2, 6, 5},
                           {2, 3, 7, 6}, {3, 4, 8, 7}, {4, 1, 5, 8}};
  const int b = first_vertex - 1;
  for (const auto& q : faces) {
    out << "f " << b + q[0] << " " << b + q[1] << " " << b + q[2] << " " << b + q[3] << "\n";
  }
  return out.str();
}

}  // namespace sandbox::testing
