#include "model_summary.hpp"

#include "command.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <fmt/core.h>
#include <numbers>

namespace servotwin::cli {

namespace {

std::string root_text(const core::ModalInfo& m) {
  if (!std::isfinite(m.freq_hz)) return "at infinity";
  if (m.root.imag() != 0.0) return fmt::format("{:.2f} Hz, zeta {:.3f}", m.freq_hz, m.zeta);
  return fmt::format("{:.2f} Hz real{}", m.freq_hz, m.root.real() > 0.0 ? " (UNSTABLE)" : "");
}
/// The solver's model (before refinement) and what the output-error refinement made of it.
void print_refinement(const vcnc::AxisIdentification& r) {
  const auto& s = r.solution;
  const auto& f = *r.refinement;
  fmt::print("  solver's model: wn {:.3f} Hz, zeta {:.4f}, p {:.3f} Hz; {}\n", s.wn / kTwoPi, s.zeta, s.p / kTwoPi,
             s.kkt_case.empty() ? "" : "case " + s.kkt_case);
  fmt::print("  output-error refinement: fit nrmse {:.4f} -> {:.4f}, {} iterations, {} simulations, {:.1f} ms ({})\n",
             r.solver_fit ? r.solver_fit->nrmse : std::nan(""), r.fit ? r.fit->nrmse : std::nan(""), f.iterations,
             f.simulations, f.time_ms, f.stop_reason);
}
/// Tells the user when the reading's encoder count alone keeps the score from zero, so a
/// quantized short-stroke error is not taken for a bad model (the thesis's 1.25 um ball screw).
void print_quantization_floor(const rapid::FitMetrics& f, const std::string& unit) {
  if (f.quantization_floor < 0.01) return;  // below 1 % it does not change what a score means
  fmt::print("  the reading's count {:.4g} {} alone gives nrmse {:.4f} (q/sqrt(12) of the error's spread): no "
             "prediction from the command scores below it\n",
             f.reading_quantum, unit, f.quantization_floor);
}

}  // namespace

std::string roots_text(const std::vector<core::ModalInfo>& roots) {
  std::string out;
  for (const auto& m : roots)
    if (m.root.imag() >= 0.0) out += fmt::format("{}[{}]", out.empty() ? "" : " ", root_text(m));
  return out.empty() ? "none" : out;
}

void print_roots(const char* label, const std::vector<core::ModalInfo>& roots) {
  fmt::print("  {}: {}\n", label, roots_text(roots));
}

std::string bandwidth_text(const rapid::AxisModel& model) {
  const double f = model.bandwidth_hz();
  if (std::isinf(f)) return fmt::format("tracking bandwidth above the Nyquist frequency ({:.4g} Hz)", 0.5 / model.ts());
  return fmt::format("tracking bandwidth {:.2f} Hz", f);
}

void print_model_summary(const vcnc::AxisIdentification& r) {
  const auto& s = r.solution;
  const auto& c = r.coefficients();
  const rapid::AxisModel model(c, r.ts);
  fmt::print("axis {}: method {}, objective {:.6g}{} ({:.2f} ms){}\n", r.axis, rapid::method_name(s.method), s.objective,
             std::isfinite(s.lower_bound) && s.method == rapid::Method::Exact
                 ? fmt::format(", certified lower bound {:.6g}", s.lower_bound)
                 : std::string(),
             s.time_ms, s.feasible ? "" : "  [outside the bounds]");
  if (r.refinement) print_refinement(r);
  fmt::print("  a1 = {:.6g}  a2 = {:.6g}  a3 = {:.6g}\n  b0 = {:.6g}  b1 = {:.6g}  b2 = {:.6g}\n  d0 = {:.6g}  d1 = {:.6g}\n",
             c.a1, c.a2, c.a3, c.b0, c.b1, c.b2, c.d0, c.d1);
  if (r.refinement) {
    const auto& f = *r.refinement;
    fmt::print("  search: wn {:.3f} Hz, zeta {:.4f}, p {:.3f} Hz (refined)\n", f.wn / kTwoPi, f.zeta, f.p / kTwoPi);
    for (const auto& a : f.active) fmt::print("  active bound {} (cost derivative {:.4g})\n", a.name, a.multiplier);
  } else {
    fmt::print("  search: wn {:.3f} Hz, zeta {:.4f}, p {:.3f} Hz; {}\n", s.wn / kTwoPi, s.zeta, s.p / kTwoPi,
               s.kkt_case.empty() ? "" : "case " + s.kkt_case);
    for (const auto& a : s.active) fmt::print("  active bound {} (multiplier {:.4g})\n", a.name, a.multiplier);
  }
  print_roots("poles", model.poles());
  print_roots("zeros", model.zeros());
  fmt::print("  {}; {}\n", model.is_stable() ? "stable" : "UNSTABLE", bandwidth_text(model));
  if (!r.shift_trials.empty()) {
    fmt::print("  command shift {} samples, chosen by fit from:", r.regressors.command_shift);
    double best = std::numeric_limits<double>::infinity(), chosen = best;
    bool any_stable = false;
    for (const auto& t : r.shift_trials) {
      any_stable = any_stable || t.stable;
      fmt::print(" {}:{}{:.4f}{}", t.shift, t.complete ? "" : ">", t.nrmse, t.stable ? "" : "(unstable)");
      best = std::min(best, t.nrmse);
      if (t.shift == r.regressors.command_shift) chosen = t.nrmse;
    }
    fmt::print("\n");
    // Issue 27 §4: a choice that is not the lowest nrmse needs its rule stated.
    if (chosen > best)
      fmt::print("  (the rule: {}the smallest |shift| whose nrmse is within {:g} % of the best)\n",
                 any_stable ? "of the stable models, " : "", 100.0 * vcnc::kShiftFitTolerance);
  } else if (r.regressors.command_shift != 0) {
    fmt::print("  command shift {} samples\n", r.regressors.command_shift);
  }
  if (r.fit)
    fmt::print("  fit (simulated tracking error): rms {:.4g} of {:.4g} {}, nrmse {:.4f}\n", r.fit->rms_difference,
               r.fit->rms_measured, r.length_unit, r.fit->nrmse);
  if (r.validation)
    fmt::print("  validation: rms {:.4g} of {:.4g} {}, nrmse {:.4f}{}\n", r.validation->rms_difference,
               r.validation->rms_measured, r.length_unit, r.validation->nrmse,
               r.solver_validation ? fmt::format(" (solver's model before refinement: {:.4f})", r.solver_validation->nrmse)
                                   : std::string());
  print_quantization_floor(r.validation ? *r.validation : r.fit ? *r.fit : rapid::FitMetrics{}, r.length_unit);
  for (const auto& w : s.warnings) fmt::print("  warning: {}\n", w);
}

}  // namespace servotwin::cli
