#pragma once
// Writing HTML reports from the commands (`--report FILE`): one self-contained file, written whole
// or not at all, never replacing an existing file without --force.

#include <memory>
#include <string>

#include "command.hpp"
#include "servotwin/report/document.hpp"

namespace servotwin::cli {

/// Adds `--report FILE` to `command`, storing the path in `path`.
void add_report_option(CLI::App& command, std::string& path);

/// Opens the report file before the work starts, so that an existing file (without --force) or an
/// unwritable directory stops the command before it has written anything else. nullptr when
/// `path` is empty (no report asked for).
std::shared_ptr<io::OutputFile> open_report(const std::string& path, const GlobalOptions& global);

/// Writes `doc` as HTML into `out`, commits it and reports its size on stderr.
void write_report(const report::Document& doc, io::OutputFile& out, const GlobalOptions& global);

}  // namespace servotwin::cli
