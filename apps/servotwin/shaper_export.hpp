#pragma once
// `--export klipper|rrf|table` of `shaper design` and `shaper select`: a shaper written as a
// firmware takes it (io/firmware_shaper.hpp), to standard output or -o.
#include <CLI/CLI.hpp>

#include <string>

#include "command.hpp"
#include "servotwin/shaping/shaper.hpp"

namespace servotwin::cli {

struct ShaperExport {
  std::string target;       ///< "", "klipper", "rrf" or "table"
  std::string axis = "x";   ///< Klipper's axis
  std::string rrf_version = "3.5";
  /// Adds --export, --export-axis and --rrf-version.
  void add_to(CLI::App& command);
  [[nodiscard]] bool requested() const noexcept { return !target.empty(); }
  /// The firmware text (notes as comments in it); core::InputError naming --export when the
  /// firmware cannot take the shaper.
  [[nodiscard]] std::string text(const shaping::Shaper& shaper) const;
};

}  // namespace servotwin::cli
