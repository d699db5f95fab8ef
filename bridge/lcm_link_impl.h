#pragma once
// Bridge-internal: the LCM handle inside LcmLink. Includes LCM's C++ header.

#include <lcm/lcm-cpp.hpp>

#include "bridge/lcm_link.h"

namespace sandbox::bridge {

struct LcmLink::Impl {
  explicit Impl(const std::string& url) : lcm(url) {}
  lcm::LCM lcm;
};

}  // namespace sandbox::bridge
