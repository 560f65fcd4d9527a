#pragma once
/// \file
/// Frequency-response CSV (design.md "frequency-response CSV"). As written:
///
///     # format: servotwin.frf/1
///     # quality: coherence            (or: thd)
///     # duration_s: 20                (only when known)
///     # <free comment lines given by the writer, e.g. "method: multisine ...">
///     freq_hz,re,im,mag_db,phase_deg,coherence_or_thd,snr,amplitude,std
///     11,-0.022048652927193185,-0.00409197136285306,-32.98529309931212,-169.4861952670179,...
///
/// (the first line of `servotwin frf estimate` on the FdiTools MultisineTypeA recording).
/// `mag_db` = 20·log10|P|, `phase_deg` = arg P in (−180, 180], `coherence_or_thd` = the point's
/// quality (its meaning given by `# quality:`), `snr` linear (0 = unknown), `amplitude` in input
/// units, `std` = the standard deviation of P (complex circular, 0 = unknown). Numbers are
/// written in shortest round-trip form.
///
/// The reader needs `freq_hz` and either `re, im` or `mag_db, phase_deg` (re/im win when both are
/// present); the quality column (`coherence_or_thd`, or `coherence` / `thd`, which also set the
/// kind), `snr`, `amplitude` and `std` are optional (0 when absent). Columns may come in any
/// order; unknown columns and `#` comments are ignored, except `# format:` (major version must
/// be 1), `# quality:` and `# duration_s:`.

#include <cstddef>
#include <iosfwd>
#include <string>
#include <string_view>
#include <vector>

#include "servotwin/core/frequency_response.hpp"

namespace servotwin::io {

/// Options of the reader.
struct FrfReadOptions {
  /// Fewest points accepted.
  std::size_t min_points = 2;
};

/// Reads a frequency-response CSV. Throws core::InputError naming `source_name`:line:column and
/// the CSV column for: an empty file, missing columns (listing the present ones), a wrong field
/// count, text/NaN/inf in a number, a frequency that is not > 0 or not increasing, a negative
/// quality/snr/amplitude/std, an unknown format version or quality kind, a bad duration, fewer
/// than `min_points` rows.
core::FrequencyResponse read_frf_csv(std::istream& in, std::string_view source_name, const FrfReadOptions& options = {});

/// Opens `path` and reads it (core::InputError if it cannot be opened).
core::FrequencyResponse read_frf_file(const std::string& path, const FrfReadOptions& options = {});

/// Writes the format above; `comments` become extra `# ` lines after the standard ones.
/// std::invalid_argument for non-increasing or non-finite frequencies or values.
void write_frf_csv(std::ostream& out, const core::FrequencyResponse& response,
                   const std::vector<std::string>& comments = {});

}  // namespace servotwin::io
