#include <algorithm>
#include <cmath>
#include <complex>
#include <fmt/format.h>
#include <vector>

#include "servotwin/core/error.hpp"
#include "servotwin/fit/plant_model.hpp"

namespace servotwin::fit {

namespace {

using Complex = std::complex<double>;

/// Roots split into real roots and the upper members of complex pairs, by a tolerance relative to
/// the largest root (a repeated or lightly damped root pair has an imaginary part far above it).
struct SplitRoots {
  std::vector<double> real;
  std::vector<Complex> pairs;  // Im > 0, sorted by modulus
};

SplitRoots split(const std::vector<Complex>& roots) {
  double scale = 0.0;
  for (const Complex& r : roots) scale = std::max(scale, std::abs(r));
  SplitRoots s;
  for (const Complex& r : roots) {
    if (std::abs(r.imag()) <= 1e-9 * std::max(scale, 1e-300)) {
      s.real.push_back(r.real());
    } else if (r.imag() > 0.0) {
      s.pairs.push_back(r);
    }
  }
  std::sort(s.pairs.begin(), s.pairs.end(), [](Complex a, Complex b) { return std::abs(a) < std::abs(b); });
  return s;
}

/// ω and ζ of a complex pair; a damping within rounding of 0 (an undamped chain) is 0.
ModalPair modal(Complex root, const std::string& field, const char* what) {
  const double w = std::abs(root);
  double zeta = -root.real() / w;
  if (std::abs(zeta) < 1e-9) zeta = 0.0;
  if (zeta < 0.0) {
    throw core::InputError(core::at_field(field), fmt::format("unstable {} pair at {:.6g} {:+.6g}j: expected a stable plant", what,
                                                              root.real(), root.imag()));
  }
  return {w, zeta};
}

}  // namespace

PlantModel plant_model_from_transfer_function(const core::TransferFunction& velocity_tf, const std::string& field) {
  const core::TransferFunction tf = velocity_tf.normalized();
  const int rel_degree = tf.den().degree() - tf.num().degree();
  if (rel_degree != 1 && rel_degree != 2) {
    throw core::InputError(core::at_field(field),
                           fmt::format("expected a motor velocity per torque with relative degree 1 (K/s at high frequency), "
                                       "or 2 with a first-order lag, got {}; for a position output divide by s first",
                                       rel_degree));
  }
  const SplitRoots poles = split(tf.den().roots());
  const SplitRoots zeros = split(tf.num().roots());
  if (!zeros.real.empty()) {
    throw core::InputError(core::at_field(field), fmt::format("real zero at {:.6g}: not an antiresonance of a flexible mode "
                                                              "(non-collocated output or extra dynamics)",
                                                              zeros.real.front()));
  }
  const std::size_t real_poles = static_cast<std::size_t>(rel_degree);  // the rigid mode, and the lag
  if (poles.real.size() != real_poles) {
    throw core::InputError(
        core::at_field(field),
        rel_degree == 1
            ? fmt::format("expected exactly one real pole (the rigid-body mode), found {}", poles.real.size())
            : fmt::format("relative degree 2 needs exactly two real poles (the rigid-body mode and the lag), found {}",
                          poles.real.size()));
  }
  if (poles.pairs.size() != zeros.pairs.size()) {
    throw core::InputError(core::at_field(field), fmt::format("{} resonance pair(s) but {} antiresonance pair(s)",
                                                              poles.pairs.size(), zeros.pairs.size()));
  }
  PlantModel m;
  m.gain = tf.num().leading() / tf.den().leading();
  // The slower real pole is the rigid-body mode, the faster one the lag 1/(s + tau2) (catalog A6).
  const double a = -*std::max_element(poles.real.begin(), poles.real.end());
  if (rel_degree == 2) {
    const double lag = -*std::min_element(poles.real.begin(), poles.real.end());
    if (!(lag > 0.0)) throw core::InputError(core::at_field(field), fmt::format("unstable lag pole at {:.6g}", -lag));
    m.lag_pole_rad_s = lag;
  }
  double scale = 1.0;
  for (const Complex& p : poles.pairs) scale = std::max(scale, std::abs(p));
  if (a < -1e-12 * scale) {
    throw core::InputError(core::at_field(field), fmt::format("unstable real pole at {:.6g}: expected a stable plant", -a));
  }
  if (a <= 1e-12 * scale) {
    m.rigid = RigidKind::kIntegrator;
  } else {
    m.rigid = RigidKind::kRealPole;
    m.rigid_pole_rad_s = a;
  }
  for (std::size_t i = 0; i < poles.pairs.size(); ++i) {
    m.modes.push_back({modal(zeros.pairs[i], field, "zero"), modal(poles.pairs[i], field, "pole")});
  }
  if (!(m.gain > 0.0) || !std::isfinite(m.gain)) {
    throw core::InputError(core::at_field(field), fmt::format("expected a positive high-frequency gain, got {}", m.gain));
  }
  return m;
}

}  // namespace servotwin::fit
