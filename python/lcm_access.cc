#include "python/lcm_access.h"

#include <pybind11/stl.h>

#include <chrono>
#include <cstdint>
#include <deque>
#include <lcm/lcm-cpp.hpp>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "bridge/lcm_link.h"
#include "bridge/lcm_link_impl.h"

namespace py = pybind11;

namespace sandbox::python {
namespace {

py::bytes Bytes(const std::vector<std::uint8_t>& data) {
  return py::bytes(reinterpret_cast<const char*>(data.data()), data.size());
}

// A message as received: channel, receive time (microseconds), bytes.
struct Received {
  std::string channel;
  std::int64_t utime;
  std::vector<std::uint8_t> data;
};

// An LCM link that hears every channel and keeps what arrives, oldest first,
// up to `capacity` messages (then the oldest go, counted in dropped).
class Link {
 public:
  Link(const std::string& url, std::size_t capacity) : link_(url), capacity_(capacity) {
    subscription_ = link_.impl().lcm.subscribeFunction("(?s).*", &Link::Deliver, this);
    if (subscription_ == nullptr) throw std::runtime_error("cannot subscribe on " + link_.url());
  }
  ~Link() { link_.impl().lcm.unsubscribe(subscription_); }

  const std::string& url() const { return link_.url(); }
  std::int64_t dropped() const { return dropped_; }

  void Publish(const std::string& channel, const py::bytes& data) {
    const std::string_view view = data;
    if (!link_.Publish(channel, view.data(), unsigned(view.size()))) {
      throw std::runtime_error("cannot publish on " + channel + " (" + link_.url() + ")");
    }
  }

  // What arrived: waits up to timeout_s for the first message when none is
  // waiting, then takes everything already there.
  std::vector<std::tuple<std::string, std::int64_t, py::bytes>> Receive(double timeout_s) {
    {
      py::gil_scoped_release release;
      const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
      link_.Drain(0.05);
      while (queue_.empty()) {
        const double left_ms =
            std::chrono::duration<double, std::milli>(end - std::chrono::steady_clock::now())
                .count();
        if (left_ms <= 0.0) break;
        // In slices, so that Ctrl-C is seen.
        if (link_.Wait(int(std::min(left_ms, 100.0)) + 1)) link_.Drain(0.05);
        py::gil_scoped_acquire acquire;
        if (PyErr_CheckSignals() != 0) throw py::error_already_set();
      }
    }
    std::vector<std::tuple<std::string, std::int64_t, py::bytes>> messages;
    messages.reserve(queue_.size());
    for (const Received& message : queue_) {
      messages.emplace_back(message.channel, message.utime, Bytes(message.data));
    }
    queue_.clear();
    return messages;
  }

 private:
  static void Deliver(const lcm::ReceiveBuffer* buffer, const std::string& channel, Link* self) {
    const auto* bytes = static_cast<const std::uint8_t*>(buffer->data);
    if (self->queue_.size() >= self->capacity_) {
      self->queue_.pop_front();
      ++self->dropped_;
    }
    self->queue_.push_back({channel, buffer->recv_utime, {bytes, bytes + buffer->data_size}});
  }

  bridge::LcmLink link_;
  lcm::Subscription* subscription_{nullptr};
  std::size_t capacity_;
  std::deque<Received> queue_;
  std::int64_t dropped_{0};
};

}  // namespace

void BindLcm(py::module_& module) {
  py::class_<Link>(module, "_Link",
                   "An LCM link hearing every channel (bridge::LcmLink; the URL as the C++ tools "
                   "take it). sandbox.Client is the interface.")
      .def(py::init<const std::string&, std::size_t>(), py::arg("url") = "",
           py::arg("capacity") = 10000)
      .def_property_readonly("url", &Link::url)
      .def_property_readonly("dropped", &Link::dropped)
      .def("publish", &Link::Publish, py::arg("channel"), py::arg("data"))
      .def("receive", &Link::Receive, py::arg("timeout") = 0.0,
           "[(channel, receive utime, bytes)], oldest first; waits up to timeout s for the "
           "first");

  py::class_<bridge::EventReader>(module, "_LogReader",
                                  "An LCM log or MCAP file read event by event "
                                  "(bridge::EventReader). sandbox.read_log is the interface.")
      .def(py::init(&bridge::OpenEventReader), py::arg("path"))
      .def(
          "next",
          [](bridge::EventReader& reader) -> py::object {
            std::string channel;
            std::vector<std::uint8_t> data;
            std::int64_t utime = 0;
            bool more = false;
            {
              py::gil_scoped_release release;
              more = reader.Next(&channel, &data, &utime);
            }
            if (!more) return py::none();
            return py::make_tuple(channel, utime, Bytes(data));
          },
          "(channel, utime, bytes), or None at the end")
      .def_property_readonly("events", &bridge::EventReader::events)
      .def_property_readonly("skipped", &bridge::EventReader::skipped)
      .def_property_readonly("stopped_early", &bridge::EventReader::stopped_early);
}

}  // namespace sandbox::python
