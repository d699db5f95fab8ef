#pragma once
// Bridge-internal: the LCM handle inside LcmLink. Includes LCM's C++ header.

#include <lcm/lcm-cpp.hpp>
#include <memory>

#include "bridge/lcm_link.h"

namespace sandbox::bridge {

struct LcmLink::Impl {
  explicit Impl(const std::string& url) : lcm(url) {}
  lcm::LCM lcm;
  std::unique_ptr<lcm::LogFile> record;
};

}  // namespace sandbox::bridge
