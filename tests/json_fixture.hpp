#pragma once
// Reading the scipy-generated JSON fixtures under tests/data/ (shared by every test module).
#include <fstream>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

namespace servotwin::test_support {

/// tests/data/<relative> parsed; std::runtime_error naming the generating script when missing.
inline nlohmann::json read_json_fixture(const std::string& relative, const std::string& script) {
  const std::string path = std::string(SERVOTWIN_TEST_DATA_DIR) + "/" + relative;
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open " + path + " (run tools/reference/" + script + ")");
  return nlohmann::json::parse(in);
}

}  // namespace servotwin::test_support
