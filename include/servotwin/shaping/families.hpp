#pragma once
/// \file
/// The classic input-shaper families, with the meaning Klipper gives them (peers A1) so that
/// results compare one to one, each designed for a known frequency and damping (the damping is
/// always used, never assumed zero):
///
/// * ZV, ZVD, ZVDD: zero vibration at the mode plus zero first / second derivative with respect
///   to frequency (Singer–Seering); impulses every half damped period T_d/2 with amplitudes
///   ∝ binomial(n, i)·K^i, K = exp(−ζπ/√(1−ζ²)).
/// * MZV (Klipper's default): three impulses spaced 3/8 of the damped period (duration 0.75·T_d)
///   with zero vibration at the mode: in the undamped frame a = (1 − 1/√2)·[1, √2, 1], i.e.
///   a_1 = a_3 = 1 − 1/√2, a_2 = √2 − 1, then A_i ∝ a_i K^i with K = exp(−0.75·ζπ/√(1−ζ²)).
///   Identical impulses to Klipper's `mzv` for the same frequency and damping (after Klipper's
///   1/ΣA normalization).
/// * EI, 2-hump EI, 3-hump EI (vibration tolerance V_tol, default 5 %): derived here by solving
///   their defining conditions for the given damping with Newton's method (forward-mode automatic
///   differentiation, continuation in ζ from the undamped closed forms):
///   - EI (3 impulses): V(ω_n) = V_tol with ∂V/∂ω = 0 there (a hump at the mode), and zero
///     vibration at one frequency below and one above;
///   - 2-hump EI (4 impulses): zero vibration at ω_n, two humps V = V_tol (∂V/∂ω = 0) on either
///     side, and zeros beyond each hump;
///   - 3-hump EI (5 impulses): a hump V_tol at ω_n, two more humps V_tol on either side, and four
///     zeros between and beyond them.
///   Undamped, these reproduce Singhose's closed forms exactly. The first design of a family for a
///   vibration tolerance tabulates its exact solutions every 0.01 in ζ (0.2–1.4 ms, once per
///   tolerance, shared by all threads); every later design starts from the table's Hermite
///   interpolation and converges in a few chord steps (1–4 µs). Klipper instead evaluates
///   polynomial curve fits in ζ (from Singhose's papers, fixed V_tol = 5 % for the hump variants,
///   t_last fixed at T_d for EI). Against the exact solutions the fits differ by at most 2e-3 in
///   amplitudes, but up to 0.15–0.18 rad/ω_n (2.5–2.8 % of a period) in impulse times at the top
///   of their damping range (EI ζ = 0.3, 3-hump ζ = 0.15), and the fitted EI's vibration at the
///   design frequency is 4.8–5.1 % instead of exactly 5 %; the fitted 2-hump EI leaves 0.3 %
///   at the mode instead of 0 (tests/data/shaping/ei_family.json records the differences per
///   case, tools/reference/shaping_reference.py computes them).
///
/// Times are in s, ω in rad/s; amplitudes sum to 1. Bad arguments throw core::InputError naming
/// the argument (omega must be finite and > 0, zeta in [0, 1), v_tol in (0, 0.5)).

#include <string>
#include <string_view>
#include <vector>

#include "servotwin/shaping/shaper.hpp"

namespace servotwin::shaping {

/// Shaper families known by name ("zv", "zvd", "zvdd", "mzv", "ei", "2hump_ei", "3hump_ei",
/// "zv4").
enum class ShaperType { kZv, kZvd, kZvdd, kMzv, kEi, kTwoHumpEi, kThreeHumpEi, kZv4 };

/// The file / command-line name of a type.
[[nodiscard]] std::string_view to_string(ShaperType type) noexcept;
/// Parses a type name; throws core::InputError naming `field` and listing the known names.
[[nodiscard]] ShaperType parse_shaper_type(std::string_view name, std::string_view field = "type");
/// All type names, in enum order.
[[nodiscard]] std::vector<std::string> shaper_type_names();

/// Default vibration tolerance of the EI family (Klipper's 1/SHAPER_VIBRATION_REDUCTION).
inline constexpr double kDefaultVibrationTolerance = 0.05;

Shaper zv_shaper(double omega, double zeta);
Shaper zvd_shaper(double omega, double zeta);
Shaper zvdd_shaper(double omega, double zeta);
Shaper mzv_shaper(double omega, double zeta);
/// EI, 2-hump and 3-hump EI solved from their defining conditions (see the file comment). Throws
/// core::InputError when no such shaper exists for the damping (the solution would need negative
/// amplitudes or non-increasing times — in practice beyond ζ ≈ 0.4 / 0.3 / 0.2, Klipper's limits).
Shaper ei_shaper(double omega, double zeta, double v_tol = kDefaultVibrationTolerance);
Shaper two_hump_ei_shaper(double omega, double zeta, double v_tol = kDefaultVibrationTolerance);
Shaper three_hump_ei_shaper(double omega, double zeta, double v_tol = kDefaultVibrationTolerance);

/// Designs any family except kZv4 (which needs its p-parameters: zv4.hpp). v_tol is used by the
/// EI family only.
Shaper design_shaper(ShaperType type, double omega, double zeta, double v_tol = kDefaultVibrationTolerance);

}  // namespace servotwin::shaping
