#pragma once
// Where a mesh's back faces can never be seen, so that a draw may cull them
// without a pixel changing (but a pixel whose centre lies on a silhouette's
// edge, which the rasterizer may give to the back face there). Two shapes
// qualify:
//  - solids: closed meshes wound counter-clockwise seen from outside; from
//    outside their box, the nearest surface on every line of sight is a
//    front face;
//  - height fields: meshes that are the graph of a height over a convex
//    footprint, wound counter-clockwise seen from above (a terrain); from
//    above the surface and over the footprint, likewise.
// Either way the near plane must not cut the surface open: the eye keeps
// farther from it than the near plane's corners.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

namespace sandbox::render {

class HiddenBackFaces {
 public:
  enum class Shape { kNone, kSolid, kHeightField };

  // The shape of `positions` and `indices` (a triangle list; vertices at one
  // position are taken as one, triangles with two corners at one position
  // are left out). kNone for anything else, and for no triangles:
  //  - solid: every edge run as often one way as the other, and each
  //    connected piece enclosing a positive volume;
  //  - height field: every triangle facing up, each edge run at most once
  //    each way, the open edges on the footprint's convex hull, and the
  //    triangles' areas seen from above adding up to the hull's (each point
  //    of the footprint under exactly one triangle).
  static HiddenBackFaces Of(const std::vector<Eigen::Vector3f>& positions,
                            const std::vector<std::uint32_t>& indices);

  // The union of two solids' (none with anything else: kNone).
  static HiddenBackFaces Union(const HiddenBackFaces& a, const HiddenBackFaces& b);

  Shape shape() const { return shape_; }
  const Eigen::AlignedBox3f& box() const { return box_; }

  // Whether no back face can be seen from `eye` (the mesh's frame) with the
  // near plane's corners `near_reach` from it.
  bool HiddenFrom(const Eigen::Vector3f& eye, float near_reach) const;

 private:
  // The range of cells (clamped to the grid) under the x, y box [low, high].
  void Cells(const Eigen::Vector2f& low, const Eigen::Vector2f& high, int* x0, int* x1, int* y0,
             int* y1) const;

  Shape shape_{Shape::kNone};
  Eigen::AlignedBox3f box_;
  // Height fields: the footprint's hull (counter-clockwise) and the highest
  // surface over each cell of a grid over the box's x and y.
  std::vector<Eigen::Vector2f> hull_;
  int cells_x_{0}, cells_y_{0};
  Eigen::Vector2f cell_size_{1.f, 1.f};
  std::vector<float> top_;
};

}  // namespace sandbox::render
