#pragma once
// The field a constructor's core::InputError names, or "<no error>" (shared by the frf tests).
#include <string>

#include "servotwin/core/error.hpp"

namespace servotwin::frf::test {

template <typename Make>
std::string field_of(Make&& make) {
  try {
    make();
  } catch (const core::InputError& e) {
    return e.where().field;
  }
  return "<no error>";
}

}  // namespace servotwin::frf::test
