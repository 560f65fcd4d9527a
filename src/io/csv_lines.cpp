#include "csv_lines.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <istream>

namespace servotwin::io::detail {

namespace {
bool is_blank(char c) noexcept { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

std::string_view trim(std::string_view s, std::size_t& offset) noexcept {
  std::size_t b = 0;
  while (b < s.size() && is_blank(s[b])) ++b;
  std::size_t e = s.size();
  while (e > b && is_blank(s[e - 1])) --e;
  offset = b;
  return s.substr(b, e - b);
}

std::string printable(std::string_view text) { return core::printable(text); }
}  // namespace

void check_header_delimiter(const std::vector<Field>& header, char delimiter, const core::SourceLocation& where,
                            std::string_view option) {
  if (header.size() != 1) return;
  for (const char other : {',', ';', '\t', '|'}) {
    if (other == delimiter || header.front().text.find(other) == std::string_view::npos) continue;
    const std::string shown = other == '\t' ? "tab" : std::string("'") + other + "'";
    const std::string remedy = option.empty() ? "save it comma-separated" : "read it with " + std::string(option) + " " + shown;
    throw core::InputError(where, "the header is a single column '" + printable(header.front().text) + "': the file looks " +
                                      shown + "-separated (" + remedy + ")");
  }
}

void split_csv_line(std::string_view line, std::vector<Field>& fields, char delimiter) {
  fields.clear();
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(delimiter, start);
    const std::size_t end = comma == std::string_view::npos ? line.size() : comma;
    std::size_t offset = 0;
    std::string_view text = trim(line.substr(start, end - start), offset);
    if (text.size() >= 2 && text.front() == '"' && text.back() == '"') {
      text = text.substr(1, text.size() - 2);
      ++offset;
    }
    fields.push_back(Field{text, start + offset + 1});
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
}

void split_blank_separated(std::string_view line, std::vector<Field>& fields) {
  fields.clear();
  std::size_t i = 0;
  while (true) {
    while (i < line.size() && is_blank(line[i])) ++i;
    if (i == line.size()) return;
    const std::size_t start = i;
    while (i < line.size() && !is_blank(line[i])) ++i;
    fields.push_back(Field{line.substr(start, i - start), start + 1});
  }
}

std::size_t read_header_line(std::istream& in, const std::string& source, std::string& line, std::string_view expected,
                             const std::function<void(const std::string&, std::size_t)>& on_skipped) {
  std::size_t line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    if (line_number == 1 && line.size() >= 3 && line.compare(0, 3, "\xEF\xBB\xBF") == 0) line.erase(0, 3);
    if (!is_skippable_line(line)) return line_number;
    if (on_skipped) on_skipped(line, line_number);
  }
  throw core::InputError({source, line_number, 0, ""}, "empty file: expected " + std::string(expected));
}

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

bool next_data_row(std::istream& in, const std::string& source, std::string& line, std::size_t& line_number,
                   std::vector<Field>& fields, std::size_t field_count) {
  while (std::getline(in, line)) {
    ++line_number;
    if (is_skippable_line(line)) continue;
    split_csv_line(line, fields);
    if (fields.size() != field_count)
      throw core::InputError({source, line_number, 0, ""}, "expected " + std::to_string(field_count) +
                                                               " fields as in the header, found " +
                                                               std::to_string(fields.size()));
    return true;
  }
  return false;
}

bool is_skippable_line(std::string_view line, std::string_view prefix) noexcept {
  std::size_t i = 0;
  while (i < line.size() && is_blank(line[i])) ++i;
  return i == line.size() || line.substr(i, prefix.size()) == prefix;
}

double parse_number(const Field& field, const core::SourceLocation& where, std::string_view column_name) {
  // The location is copied only for an error: this runs for every value of a trace.
  const auto at = [&] {
    core::SourceLocation located = where;
    located.column = field.column;
    return located;
  };
  std::string_view text = field.text;
  if (text.empty()) throw core::InputError(at(), "column '" + std::string(column_name) + "': empty value, expected a number");
  if (text.front() == '+') text.remove_prefix(1);
  double value = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec == std::errc::result_out_of_range)
    throw core::InputError(at(), "column '" + std::string(column_name) + "': number '" + printable(field.text) +
                                     "' is out of range");
  if (ec != std::errc() || end != text.data() + text.size())
    throw core::InputError(at(), "column '" + std::string(column_name) + "': expected a number, found '" +
                                     printable(field.text) + "'");
  if (!std::isfinite(value))
    throw core::InputError(at(), "column '" + std::string(column_name) + "': value '" + printable(field.text) +
                                     "' is not finite (NaN and infinity are not accepted)");
  return value;
}

std::string_view trim_blanks(std::string_view s) noexcept {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

}  // namespace servotwin::io::detail
