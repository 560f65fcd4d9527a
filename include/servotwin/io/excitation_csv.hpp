#pragma once
/// \file
/// Excitation CSV (`servotwin frf excitation`): the sequence a drive's signal generator plays, one
/// sample per row, with the design in `#` comments so that `frf estimate --excitation` can read
/// the drive's recording of it. As written:
///
///     # format: servotwin.excitation/1
///     # type: multisine                 (or: chirp, sine-steps)
///     # ts: 0.001
///     # range_hz: 1 500
///     # amplitude: 2                    (the peak value)
///     # crest_factor: 1.45
///     # period_samples: 1000            (multisine and chirp)
///     # periods: 30                     (multisine and chirp)
///     # lines: 1 2 3 ... 500            (multisine and chirp: the DFT lines of one period)
///     # step: 1 0 250 750 3             (sine steps, one per step: freq_hz begin settle measure cycles)
///     t,u
///     0,0.61803
///
/// Tools that take only values read the `u` column (a drive's table, a scope's arbitrary
/// waveform); `t` is the sample time from 0 in seconds.

#include <iosfwd>
#include <string>
#include <string_view>
#include <vector>

#include "servotwin/frf/excitation_design.hpp"

namespace servotwin::io {

/// Writes the format above; `comments` become extra `# ` lines after the design.
void write_excitation_csv(std::ostream& out, const frf::Excitation& excitation,
                          const std::vector<std::string>& comments = {});

/// Reads an excitation CSV back. Throws core::InputError naming `source_name`, the line and the
/// key or column for: a missing or foreign `# format:`, an unknown type, a missing or bad key, a
/// line outside the period's lines below Nyquist, a step outside the sequence, a sample count
/// that does not match the design, or a time column that disagrees with `ts`.
frf::Excitation read_excitation_csv(std::istream& in, std::string_view source_name);

/// Opens `path` and reads it (core::InputError if it cannot be opened).
frf::Excitation read_excitation_file(const std::string& path);

}  // namespace servotwin::io
