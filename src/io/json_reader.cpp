#include "json_reader.hpp"

#include <algorithm>
#include <set>
#include <string>
#include <vector>

namespace servotwin::io::detail {

namespace {
const char* type_name(const nlohmann::json& v) { return v.type_name(); }
}  // namespace

namespace {

/// A member given twice in one object: JSON parsers keep one of them silently (nlohmann the last),
/// so a file that says two things is refused (issue 27 §3).
struct DuplicateKey {
  std::string path;
};

/// Parser callback that tracks the members of every open object and the path to them.
class DuplicateKeys {
 public:
  bool operator()(int /*depth*/, nlohmann::json::parse_event_t event, nlohmann::json& parsed) {
    using Event = nlohmann::json::parse_event_t;
    switch (event) {
      case Event::object_start:
        names_.push_back(pending_);
        keys_.emplace_back();
        pending_.clear();
        break;
      case Event::array_start:
        names_.push_back(pending_);
        keys_.emplace_back();  // never filled: arrays have no keys
        pending_.clear();
        break;
      case Event::object_end:
      case Event::array_end:
        if (!names_.empty()) names_.pop_back();
        if (!keys_.empty()) keys_.pop_back();
        break;
      case Event::key: {
        pending_ = parsed.get<std::string>();
        if (!keys_.empty() && !keys_.back().insert(pending_).second) throw DuplicateKey{path_to(pending_)};
        break;
      }
      case Event::value:
        pending_.clear();
        break;
    }
    return true;
  }

 private:
  [[nodiscard]] std::string path_to(const std::string& key) const {
    std::string out;
    for (const std::string& name : names_)
      if (!name.empty()) out += name + ".";
    return out + key;
  }
  std::vector<std::string> names_;
  std::vector<std::set<std::string>> keys_;
  std::string pending_;
};

}  // namespace

nlohmann::json parse_json_text(std::string_view text, std::string_view source_name) {
  try {
    return nlohmann::json::parse(text.begin(), text.end(), DuplicateKeys{});
  } catch (const DuplicateKey& d) {
    throw core::InputError({std::string(source_name), 0, 0, d.path},
                           "the member is given twice in one object (a JSON reader would keep only one of them)");
  } catch (const nlohmann::json::parse_error& e) {
    // e.byte is 1-based and points just past the problem; convert it to line and column.
    const std::size_t byte = std::min<std::size_t>(e.byte == 0 ? 0 : e.byte - 1, text.size());
    std::size_t line = 1, column = 1;
    for (std::size_t i = 0; i < byte; ++i) {
      if (text[i] == '\n') {
        ++line;
        column = 1;
      } else {
        ++column;
      }
    }
    std::string what = e.what();
    if (const auto pos = what.find("syntax error"); pos != std::string::npos) what = what.substr(pos);
    throw core::InputError({std::string(source_name), line, column, ""}, "invalid JSON: " + what);
  } catch (const nlohmann::json::out_of_range& e) {
    // A number such as 1e999 overflows a double while parsing; the parser does not say where.
    std::string what = e.what();
    if (const auto pos = what.find("number overflow"); pos != std::string::npos) what = what.substr(pos);
    throw core::InputError({std::string(source_name), 0, 0, ""},
                           "invalid JSON: " + what + " (a number does not fit a double)");
  }
}

JsonObject::JsonObject(const nlohmann::json& value, std::string path, std::string_view source)
    : value_(value), path_(std::move(path)), source_(source) {
  if (!value_.is_object())
    throw core::InputError({std::string(source_), 0, 0, path_.empty() ? "<document>" : path_},
                           std::string("expected a JSON object, found ") + type_name(value_));
}

std::string JsonObject::member_path(std::string_view key) const {
  return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
}

void JsonObject::fail(std::string_view key, const std::string& message) const {
  throw core::InputError({std::string(source_), 0, 0, member_path(key)}, message);
}

void JsonObject::allow_only(std::initializer_list<std::string_view> known) const {
  allow_only(std::span<const std::string_view>(known.begin(), known.size()));
}

void JsonObject::allow_only(std::span<const std::string_view> known) const {
  for (const auto& [key, value] : value_.items()) {
    if (std::find(known.begin(), known.end(), key) != known.end()) continue;
    std::string list;
    for (auto k : known) list += (list.empty() ? "" : ", ") + std::string(k);
    fail(key, "unknown field (expected one of: " + list + ")");
  }
}

bool JsonObject::has(std::string_view key) const { return value_.contains(key); }

const nlohmann::json& JsonObject::member(std::string_view key) const {
  const auto it = value_.find(key);
  if (it == value_.end()) fail(key, "missing required field");
  return *it;
}

double JsonObject::number(std::string_view key) const {
  const auto& v = member(key);
  if (!v.is_number()) fail(key, std::string("expected a number, found ") + type_name(v));
  const double x = v.get<double>();
  if (!std::isfinite(x)) fail(key, "expected a finite number");
  return x;
}

double JsonObject::number_or(std::string_view key, double fallback) const {
  return has(key) ? number(key) : fallback;
}

std::optional<double> JsonObject::optional_number(std::string_view key) const {
  if (!has(key) || member(key).is_null()) return std::nullopt;
  return number(key);
}

int JsonObject::integer_or(std::string_view key, int fallback) const {
  if (!has(key)) return fallback;
  const double x = number(key);
  if (x != std::floor(x) || std::abs(x) > 1e9) fail(key, "expected a whole number");
  return static_cast<int>(x);
}

bool JsonObject::boolean_or(std::string_view key, bool fallback) const {
  if (!has(key)) return fallback;
  const auto& v = member(key);
  if (!v.is_boolean()) fail(key, std::string("expected true or false, found ") + type_name(v));
  return v.get<bool>();
}

std::string JsonObject::string(std::string_view key) const {
  const auto& v = member(key);
  if (!v.is_string()) fail(key, std::string("expected a string, found ") + type_name(v));
  return v.get<std::string>();
}

std::string JsonObject::string_or(std::string_view key, std::string fallback) const {
  return has(key) ? string(key) : std::move(fallback);
}

JsonObject JsonObject::object(std::string_view key) const { return JsonObject(member(key), member_path(key), source_); }

std::optional<JsonObject> JsonObject::optional_object(std::string_view key) const {
  if (!has(key)) return std::nullopt;
  return object(key);
}

const nlohmann::json& JsonObject::array(std::string_view key) const {
  const auto& v = member(key);
  if (!v.is_array()) fail(key, std::string("expected an array, found ") + type_name(v));
  if (v.empty()) fail(key, "expected at least one element");
  return v;
}

}  // namespace servotwin::io::detail
