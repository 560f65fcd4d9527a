#include "servotwin/frf/excitation.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "servotwin/core/error.hpp"

namespace servotwin::frf {

namespace {

void require_positive(double value, const char* field) {
  if (!std::isfinite(value) || value <= 0.0)
    throw core::InputError(core::at_field(field), "expected a finite value > 0, got " + std::to_string(value));
}

}  // namespace

SineGenerator::SineGenerator(double ts) : ts_(ts) { require_positive(ts, "ts"); }

void SineGenerator::reset() noexcept {
  x1_ = 0.0;
  x2_ = 1.0;
}

void SineGenerator::set_frequency(double omega) noexcept {
  if (omega == omega_) return;
  omega_ = omega;
  c_ = std::cos(omega * ts_);
  s_ = std::sin(omega * ts_);
}

void SineGenerator::advance() noexcept {
  const double x1 = c_ * x1_ + s_ * x2_;
  const double x2 = -s_ * x1_ + c_ * x2_;
  const double correction = 0.5 * (3.0 - (x1 * x1 + x2 * x2));
  x1_ = x1 * correction;
  x2_ = x2 * correction;
}

SweepSchedule::SweepSchedule(SweepType type, double rate, double ts, double omega_end)
    : type_(type), rate_(rate), growth_(std::exp(rate * ts)), ts_(ts), omega_end_(omega_end) {
  require_positive(rate, "sweep_rate");
  require_positive(ts, "ts");
  require_positive(omega_end, "omega_end");
}

double SweepSchedule::next(double omega) const noexcept {
  const double stepped = type_ == SweepType::kLinear ? omega + rate_ : omega * growth_;
  return std::min(stepped, omega_end_);
}

double SweepSchedule::samples_between(double omega_begin, double omega_end) const noexcept {
  if (type_ == SweepType::kLinear) return (omega_end - omega_begin) / rate_;
  return std::log(omega_end / omega_begin) / (rate_ * ts_);
}

}  // namespace servotwin::frf
