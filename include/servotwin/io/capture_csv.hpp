#pragma once
/// \file
/// Capture files (design.md "capture CSV"): a header row, then one row per sample with `t`
/// and, per axis, `<axis>_cmd`, `<axis>_act` and optionally `<axis>_u`. Lines starting with `#`
/// are comments. Foreign files are read through a column map and a unit scale, e.g. the EMPS
/// benchmark with `x_cmd=qg, x_act=qm, scale 1000` (m -> mm).
///
/// Controller trace formats (TraceFormat), as their sources write them:
/// * LinuxCNC `halsampler` (src/hal/components/sampler_usr.c, LinuxCNC 2.9): no header; one line
///   per sample, values separated by blanks (`%f` floats, bits as 0/1, s32/u32 integers), each
///   followed by a blank; with `-t` the sample number comes first. The names come from
///   CaptureReadOptions::columns (e.g. from the HAL file, linuxcnc_config.hpp), the period from
///   CaptureReadOptions::ts. A line with one more value than names carries the sample number: it
///   must go up by one (modulo 2^32; 2.9 prints it signed, so it may wrap to negative), a jump is
///   a gap of lost samples and an error naming the line. An `overrun` line before the first sample
///   (a halsampler started late on its FIFO) is accepted, one between samples is a gap (error).
///   A last line cut short (no line end: halsampler killed) is left out.
/// * LinuxCNC `halscope` log ("Save Log", src/hal/utils/scope_files.c, 2.9): `# Sampling period is
///   <n> ns`, a row of channel names separated by `;`, then `;`-separated values (`%.14f`); no
///   time column (t = row x period); further `#` lines (newer versions) are comments. Channels
///   named after a joint's command or feedback pin are read as that axis's `_cmd` / `_act`.

#include <cstdint>

#include <iosfwd>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "servotwin/core/capture.hpp"

namespace servotwin::io {

/// Layout of a capture file.
enum class TraceFormat : std::uint8_t {
  Csv,         ///< header row of names, `delimiter`-separated values
  Halsampler,  ///< LinuxCNC halsampler output (see the file comment)
  Halscope     ///< LinuxCNC halscope log file (see the file comment)
};
/// "csv", "halsampler", "halscope".
const char* trace_format_name(TraceFormat format) noexcept;

/// How to read a capture file.
struct CaptureReadOptions {
  TraceFormat format = TraceFormat::Csv;
  /// Names of the columns of a file without a header (halsampler), one per value in file order
  /// (the sample number of `halsampler -t` not counted): our names (x_cmd, x_act, x_u, ...) or any
  /// other name (then mapped with `map`, or not read).
  std::vector<std::string> columns;
  /// CSV only: the character between values (',' ';' or '\t').
  char delimiter = ',';
  /// Lines starting with this (after blanks) are comments; not empty.
  std::string comment_prefix = "#";
  /// halscope: the axis letter of each joint, for the channels named after LinuxCNC's joint pins
  /// (`joint.J.motor-pos-cmd` -> <a>_cmd, `joint.J.motor-pos-fb` -> <a>_act; see
  /// linuxcnc_config.hpp), used where `map` does not name the column.
  std::string joint_axes = "XYZ";
  /// Our column name -> the file's column name, e.g. {"x_cmd", "qg"}. Unmapped names are looked
  /// up as themselves.
  std::vector<std::pair<std::string, std::string>> map;
  /// Factor applied to positions (`_cmd`, `_act`), e.g. 1000 to read metres as mm. Not to t or u.
  double scale = 1.0;
  /// Largest accepted deviation of a time stamp from the uniform grid, relative to ts.
  double max_jitter = 0.01;
  /// Sample period for files without a time column.
  std::optional<double> ts;
  /// Axes to read (lower-case); empty = every axis that has both `_cmd` and `_act`.
  std::vector<std::string> axes;
  /// Axes may lack `_act` (a commanded trajectory only): AxisTrace::act is then empty.
  bool allow_missing_actual = false;
  /// Read the drive outputs (`<axis>_u`) when the file has them. Readers that never use them
  /// (identification) leave them out: on an hour of three axes they are a third of the memory.
  bool read_drive_output = true;
};

/// Reads a capture from a stream in options.format, line by line: memory holds only the columns
/// used. Throws core::InputError naming `source_name`, the line and column for: an empty file, a
/// missing column, a row with the wrong number of fields, text/NaN/inf in a number, a
/// non-increasing time, jitter above `max_jitter`, fewer than 2 rows; for halsampler files: no
/// `columns` or no `ts`, fewer values on a line than names (pins), a gap in the sample numbers
/// or an `overrun` between samples; for halscope logs: no sampling-period line, or a `--ts` that
/// disagrees with it.
core::Capture read_capture_csv(std::istream& in, std::string_view source_name,
                               const CaptureReadOptions& options = {});

/// Opens `path` and reads it (core::InputError if it cannot be opened).
core::Capture read_capture_file(const std::string& path, const CaptureReadOptions& options = {});

/// Parses "name=column" as given to `--map` (core::InputError naming the option otherwise).
std::pair<std::string, std::string> parse_column_mapping(std::string_view text);

/// Writes `t` then per axis `<axis>_cmd,<axis>_act[,<axis>_u]`; numbers round-trip exactly.
void write_capture_csv(std::ostream& out, const core::Capture& capture);

}  // namespace servotwin::io
