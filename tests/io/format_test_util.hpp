#pragma once
// Helpers for the file-format tests: expected InputErrors and byte views.
#include <cstddef>
#include <functional>
#include <initializer_list>
#include <span>
#include <string>

#include <gtest/gtest.h>

#include "mlidar/core/error.hpp"

namespace mlidar::test {

/// Runs `action`, expects an InputError whose message holds every part.
inline void expect_input_error(const std::function<void()>& action, std::initializer_list<std::string> parts) {
  try {
    action();
    ADD_FAILURE() << "expected InputError";
  } catch (const InputError& e) {
    const std::string message = e.what();
    for (const auto& part : parts) EXPECT_NE(message.find(part), std::string::npos) << "'" << message << "' lacks '" << part << "'";
  }
}

inline std::span<const std::byte> bytes_of(const std::string& text) {
  return {reinterpret_cast<const std::byte*>(text.data()), text.size()};
}

}  // namespace mlidar::test
