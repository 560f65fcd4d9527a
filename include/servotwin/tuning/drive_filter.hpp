#pragma once
/// \file
/// The filters a servo drive offers at its velocity controller's output (issue 25 §5): notch,
/// low-pass and general biquad, as continuous transfer functions and as the discrete biquads a
/// drive takes (b0 b1 b2 a1 a2 at its sample time).
///
/// Definitions (physical units, s in rad/s, f in Hz, ω = 2πf):
///   notch    N(s) = (s² + 2 ζz ω s + ω²)/(s² + 2 ζp ω s + ω²), ζp = width/(2f),
///            ζz = ζp·10^(−depth/20): |N(jω)| = 10^(−depth/20) at the centre, and `width` is
///            exactly the −3 dB band of the infinitely deep notch (the two frequencies where
///            |N| = 1/√2 lie 2ζp ω apart), as drives specify a notch by centre, width and depth.
///   lowpass  ω/(s + ω) (first order), or ω²/(s² + 2ζ ω s + ω²) when a damping is given.
///   biquad   (ωp/ωz)² (s² + 2 ζz ωz s + ωz²)/(s² + 2 ζp ωp s + ωp²): unit DC gain, numerator
///            and denominator by frequency and damping (the form drives' "general biquad" takes).
///
/// Discretization: Tustin with prewarping at the filter's own frequency (notch: the centre,
/// low-pass: the corner, biquad: the numerator's or denominator's frequency, whichever has the
/// lighter damping — the sharper feature), so the discrete filter has its feature exactly where
/// the continuous one does: s = K (z − 1)/(z + 1), K = ω0/tan(ω0 ts/2). The coefficients are those
/// of H(z) = (b0 + b1 z⁻¹ + b2 z⁻²)/(1 + a1 z⁻¹ + a2 z⁻²); a first-order filter has b2 = a2 = 0.

#include <optional>
#include <string>
#include <vector>

#include "servotwin/core/state_space.hpp"
#include "servotwin/core/transfer_function.hpp"

namespace servotwin::tuning {

/// The kind of a drive filter.
enum class DriveFilterType { kNotch, kLowpass, kBiquad };

/// "notch", "lowpass", "biquad".
[[nodiscard]] std::string to_string(DriveFilterType type);

/// A filter as the user (or the automatic notch) specifies it. Frequencies in Hz.
struct DriveFilterSpec {
  DriveFilterType type = DriveFilterType::kNotch;
  double frequency_hz = 0.0;  ///< notch centre, low-pass corner, biquad numerator frequency fz
  double width_hz = 0.0;      ///< notch: −3 dB width of the infinitely deep notch (2 ζp f)
  double depth_db = 0.0;      ///< notch: attenuation at the centre, >= 0 dB
  /// low-pass: the damping of a second-order low-pass (absent: first order);
  /// biquad: the numerator damping ζz (>= 0).
  std::optional<double> damping;
  double pole_frequency_hz = 0.0;  ///< biquad: denominator frequency fp
  double pole_damping = 0.0;       ///< biquad: denominator damping ζp (> 0)
  /// Placed and sized by the tuner (`notch:auto`), not given by the user.
  bool automatic = false;
};

/// The coefficients a drive takes: H(z) = (b0 + b1 z⁻¹ + b2 z⁻²)/(1 + a1 z⁻¹ + a2 z⁻²).
struct DiscreteBiquad {
  double b0 = 1.0, b1 = 0.0, b2 = 0.0, a1 = 0.0, a2 = 0.0;
  double ts = 0.0;          ///< sample period [s]
  double prewarp_hz = 0.0;  ///< the frequency the Tustin map keeps exact
};

/// A filter with its continuous transfer function (physical s) and, at a drive period, its
/// discrete biquad.
struct DriveFilter {
  DriveFilterSpec spec;
  core::TransferFunction continuous{core::Polynomial{1.0}, core::Polynomial{1.0}};  ///< in physical s [rad/s]
  std::optional<DiscreteBiquad> discrete;  ///< at the drive's sample period (when known)
  /// Why the tuner placed it (automatic notch), or empty.
  std::string reason;
};

/// Checks the spec (finite frequencies > 0, notch width in (0, 4f], depth in [0, 200] dB,
/// dampings in range, every frequency below the Nyquist frequency 1/(2 ts) when ts is given) and
/// throws core::InputError naming `field` (the CLI passes "--drive-filter") with the value at fault.
void validate(const DriveFilterSpec& spec, std::optional<double> ts, const std::string& field = "drive_filter");

/// The continuous transfer function of the definitions above (physical s). Validates the spec.
[[nodiscard]] core::TransferFunction continuous_filter(const DriveFilterSpec& spec);

/// The frequency [rad/s] the Tustin map of `spec` is prewarped at (see the file comment).
[[nodiscard]] double prewarp_frequency(const DriveFilterSpec& spec);

/// Tustin map of a first- or second-order `filter` (physical s) at period ts, prewarped at
/// `prewarp_rad_s` (< π/ts). core::InputError (field "ts") for a period or frequency out of range,
/// std::invalid_argument for a filter of order 0 or above 2.
[[nodiscard]] DiscreteBiquad tustin_biquad(const core::TransferFunction& filter, double ts, double prewarp_rad_s);

/// The filter of `spec`, discretized when ts is given. Validates the spec.
[[nodiscard]] DriveFilter make_drive_filter(const DriveFilterSpec& spec, std::optional<double> ts,
                                            const std::string& field = "drive_filter");

/// The product of the filters' continuous transfer functions (1 for none), physical s.
[[nodiscard]] core::TransferFunction filter_chain(const std::vector<DriveFilter>& filters);

/// The series of the filters' discrete biquads as one SISO discrete state space (D = 1 and no
/// states for none). std::invalid_argument when a filter has no discrete form or its period
/// differs from ts.
[[nodiscard]] core::DiscreteStateSpace discrete_chain(const std::vector<DriveFilter>& filters, double ts);

/// The biquad's response at ω [rad/s]: H(e^{jω ts}).
[[nodiscard]] std::complex<double> response(const DiscreteBiquad& biquad, double omega_rad_s) noexcept;

}  // namespace servotwin::tuning
