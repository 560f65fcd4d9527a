#include "servotwin/core/capture.hpp"

#include <algorithm>
#include <cctype>

namespace servotwin::core {

namespace {
bool same_name(std::string_view a, std::string_view b) noexcept {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
         });
}
}  // namespace

const AxisTrace* Capture::find(std::string_view name) const noexcept {
  for (const auto& axis : axes)
    if (same_name(axis.name, name)) return &axis;
  return nullptr;
}

AxisTrace* Capture::find(std::string_view name) noexcept {
  return const_cast<AxisTrace*>(static_cast<const Capture*>(this)->find(name));
}

}  // namespace servotwin::core
