// sandbox.Message and _decode: one message of a sandbox LCM type, in C++.
// The bytes are checked (bridge::DecodeChecked: counts and lengths against
// the bytes, exactly one message) and decoded by lcm-gen's C++ types; each
// field becomes a Python value: numbers as int or float, arrays as numpy
// arrays (a variable-length array moved, not copied), strings as str. The
// field list is lcm-gen's own (message_fields.inc, made at build time by
// message_fields.py). Several times faster than lcm-gen's Python decoders,
// which python/sandbox/messages.py keeps for encoding.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <type_traits>
#include <unordered_map>
#include <utility>
#include <vector>

#include "bridge/checked_decode.h"
#include "python/lcm_access.h"
#include "sandbox_msgs/actor_placements_t.hpp"
#include "sandbox_msgs/air_data_t.hpp"
#include "sandbox_msgs/bone_values_t.hpp"
#include "sandbox_msgs/camera_command_t.hpp"
#include "sandbox_msgs/gnss_t.hpp"
#include "sandbox_msgs/ground_map_t.hpp"
#include "sandbox_msgs/imu_t.hpp"
#include "sandbox_msgs/joint_values_t.hpp"
#include "sandbox_msgs/lidar_scan_t.hpp"
#include "sandbox_msgs/range_t.hpp"
#include "sandbox_msgs/robot_pose_t.hpp"
#include "sandbox_msgs/robot_state_t.hpp"
#include "sandbox_msgs/scan_face_compact_t.hpp"
#include "sandbox_msgs/scan_face_t.hpp"
#include "sandbox_msgs/status_t.hpp"
#include "sandbox_msgs/surface_table_t.hpp"
#include "sandbox_msgs/wrench_t.hpp"

namespace py = pybind11;

namespace sandbox::python {
namespace {

py::object ToPython(const std::string& text) {
  // Bytes from anywhere: invalid UTF-8 replaced, as lcm-gen's Python types do.
  PyObject* str = PyUnicode_DecodeUTF8(text.data(), py::ssize_t(text.size()), "replace");
  if (str == nullptr) throw py::error_already_set();
  return py::reinterpret_steal<py::object>(str);
}
template <typename T>
py::object ToPython(T value) {
  static_assert(std::is_arithmetic_v<T>);
  if constexpr (std::is_floating_point_v<T>) {
    return py::float_(double(value));
  } else {
    return py::int_(value);
  }
}
template <typename T, std::size_t N>
py::object ToPython(const T (&values)[N]) {
  return py::array_t<T>(py::ssize_t(N), values);
}
template <typename T>
py::object ToPython(std::vector<T>& values) {
  if constexpr (std::is_same_v<T, std::string>) {
    py::list list(values.size());
    for (std::size_t i = 0; i < values.size(); ++i) list[i] = ToPython(values[i]);
    return std::move(list);
  } else {
    auto* owned = new std::vector<T>(std::move(values));
    const py::capsule owner(owned, [](void* p) { delete static_cast<std::vector<T>*>(p); });
    return py::array_t<T>(py::ssize_t(owned->size()), owned->data(), owner);
  }
}

// One decoded message, kept in C++; a field becomes a Python value when
// first asked for (an array is moved out: the Python object keeps it).
class Decoded {
 public:
  virtual ~Decoded() = default;
  virtual const char* type() const = 0;
  // The field as a Python value, or a null object when there is no such field.
  virtual py::object Field(std::string_view name) = 0;
  virtual const std::vector<const char*>& FieldNames() const = 0;
};

template <typename Message>
class DecodedAs : public Decoded {
 public:
  Message message;
  const char* type() const override { return Message::getTypeName(); }
  py::object Field(std::string_view name) override;
  const std::vector<const char*>& FieldNames() const override;
};

#define SANDBOX_FIELD(name) \
  if (field == #name) return ToPython(message.name);
#define SANDBOX_MESSAGE(type, FIELDS)                                       \
  template <>                                                               \
  py::object DecodedAs<sandbox_msgs::type>::Field(std::string_view field) { \
    FIELDS                                                                  \
    return py::object();                                                    \
  }
#include "message_fields.inc"
#undef SANDBOX_MESSAGE
#undef SANDBOX_FIELD
#define SANDBOX_FIELD(name) #name,
#define SANDBOX_MESSAGE(type, FIELDS)                                                        \
  template <>                                                                                \
  const std::vector<const char*>& DecodedAs<sandbox_msgs::type>::FieldNames() const {        \
    static const std::vector<const char*> names{FIELDS};                                     \
    return names;                                                                            \
  }
#include "message_fields.inc"
#undef SANDBOX_MESSAGE
#undef SANDBOX_FIELD

// Decodes `size` bytes of one type, or says why it cannot.
using Decoder = std::unique_ptr<Decoded> (*)(const std::uint8_t* data, std::size_t size,
                                             std::string* why);

template <typename Message>
std::unique_ptr<Decoded> DecodeAs(const std::uint8_t* data, std::size_t size, std::string* why) {
  auto decoded = std::make_unique<DecodedAs<Message>>();
  *why = bridge::DecodeChecked(data, size, &decoded->message);
  if (!why->empty()) decoded.reset();
  return decoded;
}

const std::unordered_map<std::uint64_t, Decoder>& Types() {
  static const auto* types = [] {
    auto* table = new std::unordered_map<std::uint64_t, Decoder>;
#define SANDBOX_MESSAGE(type, FIELDS) \
  table->emplace(std::uint64_t(sandbox_msgs::type::getHash()), &DecodeAs<sandbox_msgs::type>);
#include "message_fields.inc"
#undef SANDBOX_MESSAGE
    return table;
  }();
  return *types;
}

// The message in `size` bytes; ValueError when they are not one.
std::unique_ptr<Decoded> Decode(const std::uint8_t* begin, std::size_t size) {
  std::uint64_t fingerprint = 0;
  for (std::size_t i = 0; i < 8 && i < size; ++i) fingerprint = fingerprint << 8 | begin[i];
  const auto type = size < 8 ? Types().end() : Types().find(fingerprint);
  if (type == Types().end()) {
    static const char* hex = "0123456789abcdef";
    std::string shown;
    for (std::size_t i = 0; i < 8 && i < size; ++i) {
      shown += hex[begin[i] >> 4];
      shown += hex[begin[i] & 15];
    }
    throw py::value_error("not a sandbox message (fingerprint " +
                          (shown.empty() ? std::string("missing") : shown) + ")");
  }
  std::string why;
  std::unique_ptr<Decoded> decoded = type->second(begin, size, &why);
  if (!decoded) throw py::value_error(why);
  return decoded;
}

// The same of any bytes-like object (a strided one copied first).
std::unique_ptr<Decoded> DecodeObject(const py::handle& data) {
  Py_buffer view;
  if (PyObject_GetBuffer(data.ptr(), &view, PyBUF_SIMPLE) == 0) {
    const std::unique_ptr<Py_buffer, void (*)(Py_buffer*)> release(&view, PyBuffer_Release);
    return Decode(static_cast<const std::uint8_t*>(view.buf), std::size_t(view.len));
  }
  PyErr_Clear();
  if (!PyObject_CheckBuffer(data.ptr())) {
    throw py::type_error(std::string("decode takes bytes-like data, not ") +
                         Py_TYPE(data.ptr())->tp_name);
  }
  const py::bytes copy = py::reinterpret_steal<py::bytes>(PyBytes_FromObject(data.ptr()));
  if (!copy) throw py::error_already_set();
  const std::string_view bytes = copy;
  return Decode(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
}

// A field not read before: made, kept in the instance's __dict__ (where
// Python finds it from then on) and returned.
py::object GetField(const py::object& self, const std::string& name) {
  auto& decoded = self.cast<Decoded&>();
  py::object value;
  if (name.empty() || name[0] != '_') value = decoded.Field(name);
  if (!value) {
    std::string known;
    for (const char* field : decoded.FieldNames()) known += (known.empty() ? "" : ", ") + std::string(field);
    throw py::attribute_error(std::string(decoded.type()) + " has no field '" + name +
                              "'; it has " + known);
  }
  if (PyObject_GenericSetAttr(self.ptr(), py::str(name).ptr(), value.ptr()) != 0) {
    throw py::error_already_set();
  }
  return value;
}

py::dict Fields(const py::object& self) {
  py::dict fields;
  for (const char* name : self.cast<Decoded&>().FieldNames()) fields[name] = self.attr(name);
  return fields;
}

}  // namespace

py::list DecodeSpans(const py::handle& buffer,
                     const std::vector<std::pair<std::size_t, std::size_t>>& spans) {
  Py_buffer view;
  if (PyObject_GetBuffer(buffer.ptr(), &view, PyBUF_SIMPLE) != 0) throw py::error_already_set();
  const std::unique_ptr<Py_buffer, void (*)(Py_buffer*)> release(&view, PyBuffer_Release);
  py::list messages(spans.size());
  for (std::size_t i = 0; i < spans.size(); ++i) {
    const auto [offset, size] = spans[i];
    if (offset > std::size_t(view.len) || size > std::size_t(view.len) - offset) {
      throw py::value_error("a span runs past the buffer's end");
    }
    messages[i] = py::cast(Decode(static_cast<const std::uint8_t*>(view.buf) + offset, size));
  }
  return messages;
}

void BindDecode(py::module_& module) {
  py::class_<Decoded>(module, "Message", py::dynamic_attr(),
                      "A decoded message: its fields as attributes (as in bridge/lcmtypes/*.lcm, "
                      "flat), numeric arrays as numpy arrays, string arrays as lists, each made "
                      "when first read; `lcm_type` is the type's name, `fields()` all of them.")
      .def_property_readonly("lcm_type", &Decoded::type)
      .def("__getattr__", &GetField, py::arg("name"))
      .def("fields", &Fields, "{field: value} of every field, in the type's order")
      .def("__dir__",
           [](const Decoded& decoded) {
             py::list names;
             names.append("lcm_type");
             names.append("fields");
             for (const char* name : decoded.FieldNames()) names.append(name);
             return names;
           })
      .def("__repr__", [](const py::object& self) {
        std::string shown;
        for (const auto& [name, value] : Fields(self)) {
          shown += (shown.empty() ? "" : ", ") + std::string(py::str(name)) + "=" +
                   std::string(py::repr(value));
        }
        return std::string(self.cast<Decoded&>().type()) + "(" + shown + ")";
      });
  module.attr("Message").attr("__module__") = "sandbox";
  module.def("_decode", &DecodeObject, py::arg("data"),
             "one sandbox message's bytes decoded as a Message (ValueError when they are not "
             "one)");
  module.def("_decode_spans", &DecodeSpans, py::arg("buffer"), py::arg("spans"),
             "[Message] of the spans [(offset, size)] of one buffer");
}

}  // namespace sandbox::python
