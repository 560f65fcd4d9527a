#pragma once
// Private helper: typed access to a JSON object that reports errors with the JSON path of the
// offending member, and parses text with line:column positions for syntax errors.

#include <cmath>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <span>
#include <string_view>

#include "servotwin/core/error.hpp"

namespace servotwin::io::detail {

/// Parses JSON text; syntax errors become core::InputError with line and column.
nlohmann::json parse_json_text(std::string_view text, std::string_view source_name);

/// A JSON object together with its path ("axes[0].plant") for error messages.
class JsonObject {
 public:
  JsonObject(const nlohmann::json& value, std::string path, std::string_view source);

  /// Errors unless every member is one of `known` (typos are the usual cause).
  void allow_only(std::initializer_list<std::string_view> known) const;
  /// The same for a list built at run time (members that depend on another member).
  void allow_only(std::span<const std::string_view> known) const;

  [[nodiscard]] bool has(std::string_view key) const;
  /// Finite number (required).
  [[nodiscard]] double number(std::string_view key) const;
  /// Finite number or `fallback` when absent.
  [[nodiscard]] double number_or(std::string_view key, double fallback) const;
  /// Finite number, or empty when absent or null.
  [[nodiscard]] std::optional<double> optional_number(std::string_view key) const;
  /// Integer (required to be whole).
  [[nodiscard]] int integer_or(std::string_view key, int fallback) const;
  [[nodiscard]] bool boolean_or(std::string_view key, bool fallback) const;
  [[nodiscard]] std::string string(std::string_view key) const;
  [[nodiscard]] std::string string_or(std::string_view key, std::string fallback) const;
  /// Nested object (required).
  [[nodiscard]] JsonObject object(std::string_view key) const;
  /// Nested object or empty when absent.
  [[nodiscard]] std::optional<JsonObject> optional_object(std::string_view key) const;
  /// Array member (required, non-empty).
  [[nodiscard]] const nlohmann::json& array(std::string_view key) const;

  [[nodiscard]] std::string member_path(std::string_view key) const;
  [[nodiscard]] const std::string& path() const noexcept { return path_; }
  [[nodiscard]] std::string_view source() const noexcept { return source_; }
  /// Error at a member of this object.
  [[noreturn]] void fail(std::string_view key, const std::string& message) const;

 private:
  [[nodiscard]] const nlohmann::json& member(std::string_view key) const;
  const nlohmann::json& value_;
  std::string path_;
  std::string_view source_;
};

}  // namespace servotwin::io::detail
