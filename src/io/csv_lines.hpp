#pragma once
// Private helpers shared by the CSV readers: field splitting and strict number parsing.

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "servotwin/core/error.hpp"

namespace servotwin::io::detail {

/// One field of a CSV line: its text (trimmed, unquoted) and 1-based column of its first char.
struct Field {
  std::string_view text;
  std::size_t column = 0;
};

/// Splits `line` at commas into `fields` (reused buffer). Surrounding blanks and one pair of
/// double quotes are removed from each field.
void split_csv_line(std::string_view line, std::vector<Field>& fields);

/// True for blank lines and `#` comment lines.
bool is_skippable_line(std::string_view line) noexcept;

/// Parses a finite decimal number occupying the whole field (optional leading '+').
/// Throws core::InputError at `where` (column filled in from the field) otherwise.
double parse_number(const Field& field, core::SourceLocation where, std::string_view column_name);

}  // namespace servotwin::io::detail
