#pragma once
// Human-readable summary of an identified axis model, shared by `identify` and `solve`.

#include <string>
#include <vector>

#include "servotwin/vcnc/identification.hpp"

namespace servotwin::cli {

/// Coefficients, search variables, active bounds, poles, zeros, bandwidth and fit on stdout.
/// "  label: [1.40 Hz real] [37.51 Hz, zeta 0.431]" (one line; conjugates once).
void print_roots(const char* label, const std::vector<core::ModalInfo>& roots);

/// The roots as print_roots shows them, without the label: "[1.40 Hz real] [37.51 Hz, zeta 0.431]",
/// "none" when there are none.
std::string roots_text(const std::vector<core::ModalInfo>& roots);

/// "tracking bandwidth 21.63 Hz", or "... above the Nyquist frequency (500 Hz)" when the gain
/// never falls 3 dB below it there (a ZPETC-like loop), rather than "inf".
std::string bandwidth_text(const rapid::AxisModel& model);

void print_model_summary(const vcnc::AxisIdentification& identification);

}  // namespace servotwin::cli
