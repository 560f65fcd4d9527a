#pragma once
// Private helpers shared by the CSV readers: field splitting and strict number parsing.

#include <cstddef>
#include <functional>
#include <iosfwd>
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

/// Splits `line` at commas (or `delimiter`) into `fields` (reused buffer). Surrounding blanks and
/// one pair of double quotes are removed from each field.
void split_csv_line(std::string_view line, std::vector<Field>& fields, char delimiter = ',');

/// A header split into one column that holds another common delimiter (',', ';', tab, '|') is a
/// file with that delimiter (European spreadsheets write ';'): core::InputError at the header saying
/// so, and how to read it: with `option` (the reader's delimiter setting as the user gives it) or,
/// when empty, saved comma-separated. Returns otherwise.
void check_header_delimiter(const std::vector<Field>& header, char delimiter, const core::SourceLocation& where,
                            std::string_view option);

/// Splits `line` at runs of blanks (spaces, tabs) into `fields`; leading and trailing blanks
/// make no empty fields (halsampler ends every value with a blank).
void split_blank_separated(std::string_view line, std::vector<Field>& fields);

/// `s` without leading blanks and tabs and trailing blanks, tabs and carriage returns (for the
/// `# key: value` comments the readers take settings from).
std::string_view trim_blanks(std::string_view s) noexcept;

/// ASCII lower case (column names are matched case-insensitively).
std::string lower(std::string_view s);

/// True for blank lines and comment lines (starting with `prefix` after blanks).
bool is_skippable_line(std::string_view line, std::string_view prefix = "#") noexcept;

/// Reads lines up to the header row (the first line that is neither blank nor a `#` comment),
/// dropping a UTF-8 byte-order mark on the first line; `on_skipped(line, line_number)` sees each
/// skipped line (e.g. to read `# key: value` comments). Leaves the header in `line` and returns its
/// line number. core::InputError naming `source` ("empty file: expected <expected>") when there is
/// no header.
std::size_t read_header_line(std::istream& in, const std::string& source, std::string& line,
                             std::string_view expected,
                             const std::function<void(const std::string&, std::size_t)>& on_skipped = {});

/// Reads the next data row (skipping blank and comment lines) into `fields`, counting lines in
/// `line_number`; false at the end of the input. core::InputError at the line when the row does
/// not have `field_count` fields, as the header.
bool next_data_row(std::istream& in, const std::string& source, std::string& line, std::size_t& line_number,
                   std::vector<Field>& fields, std::size_t field_count);

/// Parses a finite decimal number occupying the whole field (optional leading '+').
/// Throws core::InputError at `where` (column filled in from the field) otherwise.
double parse_number(const Field& field, const core::SourceLocation& where, std::string_view column_name);

}  // namespace servotwin::io::detail
