// The genetic algorithm of thesis section 4.2, and its reproducible random numbers.
//
// One generation t = 1, 2, ... (the parents of t = 1 are uniform in the bounds, section 4.2.1):
//  1. crossover (Eq. 4.3, SBX with n = 2): the parents are matched by a uniform random permutation
//     (pairs 0-1, 2-3, ... of it; an odd one out passes unchanged); with probability crossover_rate a
//     pair draws r ~ U[0, 1), alpha = (2r)^(1/3) or (2(1 - r))^(1/3), and is replaced by
//     (1 +- alpha)/2 v_i + (1 -+ alpha)/2 v_j, else it passes unchanged;
//  2. mutation (Eq. 4.4-4.6): with probability mutation_rate a candidate draws N_i and
//     eta = exp(tau' N_t + tau N_i), tau = 1/sqrt(2 sqrt(t)), tau' = 1/sqrt(2 t), N_t drawn once per
//     generation, and every variable k moves by R_k eta N_k with its own N_k and
//     R_k = (v_k - v_min,k)/3 for N_k <= 0, (v_max,k - v_k)/3 otherwise;
//  3. constraint check (Eq. 4.7): clamp to the bounds;
//  4. fitness: Eq. 4.12, i.e. f with theta2 eliminated, evaluated in its factored form;
//  5. selection (section 4.2.5): the `elite` best of the mutated pool, then tournaments of two
//     candidates drawn uniformly with replacement from the pool (the better one; the first on a tie).
// The draws happen in exactly this order, so a seed fixes the run. The best candidate ever
// evaluated is returned; the history holds the best of each generation's pool.

#include <algorithm>
#include <cmath>
#include <numeric>

#include "solver_internal.hpp"

namespace servotwin::rapid::detail {

namespace {
// ln 2 split so that k * kLn2Hi is exact for |k| < 2^20 (fdlibm's constants).
constexpr double kLn2Hi = 0x1.62e42feep-1;
constexpr double kLn2Lo = 0x1.a39ef35793c76p-33;
constexpr double kInvLn2 = 0x1.71547652b82fep0;
constexpr double kSqrtHalf = 0x1.6a09e667f3bcdp-1;
}  // namespace

double deterministic_log(double x) noexcept {
  int e = 0;
  double m = std::frexp(x, &e);  // exact: x = m 2^e, m in [0.5, 1)
  if (m < kSqrtHalf) {
    m *= 2.0;
    --e;
  }
  // log m = 2 atanh(z), |z| <= 0.1716: the series to z^21 is below 1e-19.
  const double z = (m - 1.0) / (m + 1.0);
  const double z2 = z * z;
  double sum = 1.0 / 21.0;
  for (int k = 19; k >= 1; k -= 2) sum = sum * z2 + 1.0 / k;
  const double ed = e;
  return ed * kLn2Hi + (ed * kLn2Lo + 2.0 * z * sum);
}

double deterministic_exp(double x) noexcept {
  const double k = std::floor(x * kInvLn2 + 0.5);
  const double r = (x - k * kLn2Hi) - k * kLn2Lo;  // |r| <= 0.35
  double e = 1.0;
  for (int n = 17; n >= 1; --n) e = 1.0 + e * r / n;
  return std::ldexp(e, static_cast<int>(k));
}

double deterministic_cbrt(double x) noexcept {
  if (x == 0.0) return 0.0;
  int e = 0;
  const double m = std::frexp(x, &e);
  int q = e / 3;
  int rem = e - 3 * q;
  if (rem < 0) {
    rem += 3;
    --q;
  }
  const double mm = std::ldexp(m, rem);  // in [0.5, 4)
  double y = 0.7 + 0.25 * mm;            // within 10 % of mm^(1/3)
  for (int i = 0; i < 7; ++i) y = (2.0 * y + mm / (y * y)) / 3.0;
  return std::ldexp(y, q);
}

double GaRandom::uniform() noexcept { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }

double GaRandom::normal() noexcept {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  for (;;) {
    const double u = 2.0 * uniform() - 1.0;
    const double v = 2.0 * uniform() - 1.0;
    const double s = u * u + v * v;
    if (s > 0.0 && s < 1.0) {
      const double f = std::sqrt(-2.0 * deterministic_log(s) / s);
      spare_ = v * f;
      has_spare_ = true;
      return u * f;
    }
  }
}

std::uint64_t GaRandom::below(std::uint64_t n) noexcept {
  const std::uint64_t threshold = (0 - n) % n;  // 2^64 mod n
  for (;;) {
    const std::uint64_t x = engine_();
    if (x >= threshold) return x % n;
  }
}

GaResult genetic_search(const ReducedProblem& rp, const Bounds& bounds, const GaOptions& options) {
  using Candidate = std::array<double, 3>;  // (wn, zeta, p), Eq. 4.1
  const Candidate vmin{bounds.wn_min, bounds.zeta_min, bounds.p_min};
  const Candidate vmax{bounds.wn_max, bounds.zeta_max, bounds.p_max};
  const std::size_t n = options.population;
  const double half_c2 = 0.5 * rp.c() * rp.c();
  auto fitness_of = [&](const Candidate& v) { return rp.excess(theta1_from_poles(v[2], v[0], v[1])); };
  auto clamp = [&](Candidate& v) {
    for (std::size_t k = 0; k < 3; ++k) v[k] = std::clamp(v[k], vmin[k], vmax[k]);
  };

  GaRandom rng(options.seed);
  std::vector<Candidate> parents(n), pool(n);
  std::vector<double> fitness(n);
  std::vector<std::size_t> order(n), rank(n);
  for (auto& v : parents) {
    for (std::size_t k = 0; k < 3; ++k) v[k] = vmin[k] + rng.uniform() * (vmax[k] - vmin[k]);
    clamp(v);
  }
  Candidate best = parents[0];
  double best_g = fitness_of(best);
  for (const auto& v : parents) {
    const double g = fitness_of(v);
    if (g < best_g) {
      best_g = g;
      best = v;
    }
  }

  GaResult result;
  if (options.record_history) result.history.reserve(options.generations);
  const std::size_t elite = std::min(options.elite, n);
  for (std::size_t t = 1; t <= options.generations; ++t) {
    // 1. crossover
    std::iota(order.begin(), order.end(), std::size_t{0});
    for (std::size_t i = n - 1; i > 0; --i) std::swap(order[i], order[rng.below(i + 1)]);
    for (std::size_t k = 0; k + 1 < n; k += 2) {
      const std::size_t a = order[k], b = order[k + 1];
      if (rng.uniform() < options.crossover_rate) {
        const double r = rng.uniform();
        const double alpha = r < 0.5 ? deterministic_cbrt(2.0 * r) : deterministic_cbrt(2.0 * (1.0 - r));
        const double wa = 0.5 * (1.0 + alpha), wb = 0.5 * (1.0 - alpha);
        for (std::size_t m = 0; m < 3; ++m) {
          pool[a][m] = wa * parents[a][m] + wb * parents[b][m];
          pool[b][m] = wb * parents[a][m] + wa * parents[b][m];
        }
      } else {
        pool[a] = parents[a];
        pool[b] = parents[b];
      }
    }
    if (n % 2 == 1) pool[order[n - 1]] = parents[order[n - 1]];
    // 2. mutation, 3. constraint check
    const double td = static_cast<double>(t);
    const double tau = 1.0 / std::sqrt(2.0 * std::sqrt(td));
    const double tau_prime = 1.0 / std::sqrt(2.0 * td);
    const double n_t = rng.normal();
    for (auto& v : pool) {
      if (rng.uniform() < options.mutation_rate) {
        const double eta = deterministic_exp(tau_prime * n_t + tau * rng.normal());
        for (std::size_t k = 0; k < 3; ++k) {
          const double z = rng.normal();
          const double range = z <= 0.0 ? (v[k] - vmin[k]) / 3.0 : (vmax[k] - v[k]) / 3.0;
          v[k] += range * eta * z;
        }
      }
      clamp(v);
    }
    // 4. fitness
    for (std::size_t i = 0; i < n; ++i) fitness[i] = fitness_of(pool[i]);
    // 5. selection
    std::iota(rank.begin(), rank.end(), std::size_t{0});
    std::partial_sort(rank.begin(), rank.begin() + static_cast<std::ptrdiff_t>(std::max<std::size_t>(elite, 1)),
                      rank.end(), [&](std::size_t l, std::size_t r) {
                        return fitness[l] < fitness[r] || (fitness[l] == fitness[r] && l < r);
                      });
    const Candidate& generation_best = pool[rank[0]];
    if (fitness[rank[0]] < best_g) {
      best_g = fitness[rank[0]];
      best = generation_best;
    }
    if (options.record_history) {
      result.history.push_back({rp.y_norm_squared() * (fitness[rank[0]] + half_c2), generation_best[2],
                                generation_best[0], generation_best[1]});
    }
    for (std::size_t e = 0; e < elite; ++e) parents[e] = pool[rank[e]];
    for (std::size_t i = elite; i < n; ++i) {
      const std::size_t a = rng.below(n), b = rng.below(n);
      parents[i] = fitness[a] <= fitness[b] ? pool[a] : pool[b];
    }
  }
  result.p = best[2];
  result.wn = best[0];
  result.zeta = best[1];
  return result;
}

}  // namespace servotwin::rapid::detail
