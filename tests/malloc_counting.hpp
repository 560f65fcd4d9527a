#pragma once
// Counting heap allocations in a test executable, to check that per-sample paths do not allocate
// (design.md: everything that runs once per sample is allocation-free after construction).
// `malloc` is interposed: Eigen (aligned_malloc -> std::malloc) and operator new both end there.
// Interposition needs glibc's dynamic symbol lookup and conflicts with the sanitizers' own malloc,
// so under AddressSanitizer or on other C libraries counting is off and the tests skip.
//
// Include this header in exactly ONE source file of a test executable (it defines malloc/free).

#include <gtest/gtest.h>

#include <cstddef>
#include <cstring>

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

namespace servotwin::test_support {

#ifdef SERVOTWIN_NO_MALLOC_COUNTING
inline std::size_t allocations() { return 0; }
#define SKIP_WITHOUT_COUNTING() GTEST_SKIP() << "malloc counting needs glibc without sanitizers"
#else
inline std::size_t allocations() { return malloc_calls; }
#define SKIP_WITHOUT_COUNTING() (void)0
#endif

}  // namespace servotwin::test_support
