// The per-sample simulation path must not allocate (design.md: everything that runs once per
// sample is allocation-free after construction). Counting is done by interposing `malloc` in this
// test executable: Eigen (aligned_malloc -> std::malloc) and operator new both end there.
// Interposition needs glibc's dynamic symbol lookup and conflicts with the sanitizers' own
// malloc, so under AddressSanitizer or on other C libraries the tests are skipped.

#include <gtest/gtest.h>

#include <cstddef>
#include <cstring>
#include <vector>

#include "servotwin/core/state_space.hpp"

#if defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(memory_sanitizer)
#define SERVOTWIN_NO_MALLOC_COUNTING 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__) || !defined(__GLIBC__)
#define SERVOTWIN_NO_MALLOC_COUNTING 1
#endif

#ifndef SERVOTWIN_NO_MALLOC_COUNTING
#include <dlfcn.h>

namespace {

using MallocFn = void* (*)(std::size_t);
using FreeFn = void (*)(void*);

MallocFn real_malloc = nullptr;
FreeFn real_free = nullptr;
bool resolving = false;
std::size_t malloc_calls = 0;

// dlsym may itself allocate while the real malloc is being looked up; those few requests are
// served from a static arena that free() recognises and ignores.
alignas(std::max_align_t) unsigned char bootstrap_arena[16384];
std::size_t bootstrap_used = 0;

bool in_bootstrap_arena(const void* p) {
  const auto* byte = static_cast<const unsigned char*>(p);
  return byte >= bootstrap_arena && byte < bootstrap_arena + sizeof(bootstrap_arena);
}

void* bootstrap_allocate(std::size_t size) {
  constexpr std::size_t align = alignof(std::max_align_t);
  const std::size_t rounded = (size + align - 1) / align * align;
  if (bootstrap_used + rounded > sizeof(bootstrap_arena)) return nullptr;
  void* p = bootstrap_arena + bootstrap_used;
  bootstrap_used += rounded;
  return p;
}

template <typename Fn>
Fn lookup(const char* name) {
  void* symbol = dlsym(RTLD_NEXT, name);
  Fn fn = nullptr;
  std::memcpy(&fn, &symbol, sizeof(fn));  // object pointer -> function pointer without a cast warning
  return fn;
}

void resolve() {
  resolving = true;
  real_malloc = lookup<MallocFn>("malloc");
  real_free = lookup<FreeFn>("free");
  resolving = false;
}

}  // namespace

extern "C" void* malloc(std::size_t size) {
  if (real_malloc == nullptr) {
    if (resolving) return bootstrap_allocate(size);
    resolve();
  }
  ++malloc_calls;
  return real_malloc(size);
}

extern "C" void free(void* p) {
  if (p == nullptr || in_bootstrap_arena(p)) return;
  if (real_free == nullptr) resolve();
  real_free(p);
}
#endif

namespace servotwin::core {
namespace {

#ifdef SERVOTWIN_NO_MALLOC_COUNTING
std::size_t allocations() { return 0; }
#define SKIP_WITHOUT_COUNTING() GTEST_SKIP() << "malloc counting needs glibc without sanitizers"
#else
std::size_t allocations() { return malloc_calls; }
#define SKIP_WITHOUT_COUNTING() (void)0
#endif

DiscreteStateSpace two_mass_discrete() {
  // Two-mass drive of tools/reference/core_reference.py, 4 states, outputs [omega1, theta2].
  const double j1 = 1e-3, j2 = 2e-3, k = 500.0, c = 0.05;
  StateSpace s;
  s.A = Eigen::MatrixXd{{0.0, 1.0, 0.0, 0.0}, {-k / j1, -c / j1, k / j1, c / j1}, {0.0, 0.0, 0.0, 1.0}, {k / j2, c / j2, -k / j2, -c / j2}};
  s.B = Eigen::MatrixXd{{0.0}, {1.0 / j1}, {0.0}, {0.0}};
  s.C = Eigen::MatrixXd{{0.0, 1.0, 0.0, 0.0}, {0.0, 0.0, 1.0, 0.0}};
  s.D = Eigen::MatrixXd::Zero(2, 1);
  return discretize_zoh(s, 1e-3);
}

TEST(Allocation, CounterSeesEigenAndStandardAllocations) {
  SKIP_WITHOUT_COUNTING();
  // Without this the tests below could not fail.
  const std::size_t before = allocations();
  {
    std::vector<double> v(100, 1.0);
    Eigen::VectorXd e = Eigen::VectorXd::Ones(100);
    EXPECT_EQ(v.size(), static_cast<std::size_t>(e.size()));
  }
  EXPECT_GE(allocations() - before, 2U);
}

TEST(Allocation, DiscreteSimulatorStepDoesNotAllocate) {
  SKIP_WITHOUT_COUNTING();
  DiscreteSimulator sim(two_mass_discrete());
  double y[2] = {0.0, 0.0};
  const std::size_t before = allocations();
  double sum = 0.0;
  for (int k = 0; k < 10000; ++k) {
    const double u = (k / 10) % 2 == 0 ? 0.05 : -0.05;
    sim.step(std::span<const double>(&u, 1), y);
    sum += y[0] + sim.step(-u);
  }
  sim.reset();
  EXPECT_EQ(allocations() - before, 0U);
  EXPECT_TRUE(std::isfinite(sum));
}

TEST(Allocation, BatchSimulationAllocatesIndependentlyOfLength) {
  SKIP_WITHOUT_COUNTING();
  const DiscreteStateSpace d = two_mass_discrete();
  const Eigen::MatrixXd short_u = Eigen::MatrixXd::Constant(10, 1, 0.01);
  const Eigen::MatrixXd long_u = Eigen::MatrixXd::Constant(20000, 1, 0.01);
  std::size_t before = allocations();
  const Eigen::MatrixXd y_short = simulate(d, short_u);
  const std::size_t short_count = allocations() - before;
  before = allocations();
  const Eigen::MatrixXd y_long = simulate(d, long_u);
  EXPECT_EQ(allocations() - before, short_count);
  EXPECT_EQ(y_long.rows(), 20000);
  EXPECT_EQ(y_short.rows(), 10);
}

}  // namespace
}  // namespace servotwin::core
