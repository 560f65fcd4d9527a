#include "servotwin/core/parallel.hpp"

#include <algorithm>
#include <exception>
#include <system_error>
#include <thread>
#include <vector>

#if defined(__linux__)
#include <sched.h>
#endif

namespace servotwin::core {

std::size_t worker_count(std::size_t requested) noexcept {
  if (requested > 0) return requested;
#if defined(__linux__)
  // The cores this process may run on (taskset, a container's cpuset), not every core the machine has.
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  if (sched_getaffinity(0, sizeof allowed, &allowed) == 0 && CPU_COUNT(&allowed) > 0)
    return static_cast<std::size_t>(CPU_COUNT(&allowed));
#endif
  return std::max<std::size_t>(1, std::thread::hardware_concurrency());
}

void parallel_parts(std::size_t n, std::size_t workers, std::size_t min_part,
                    const std::function<void(std::size_t, std::size_t)>& body) {
  if (n == 0) return;
  const std::size_t parts = std::clamp<std::size_t>(n / std::max<std::size_t>(min_part, 1), 1, worker_count(workers));
  if (parts == 1) {
    body(0, n);
    return;
  }
  std::vector<std::exception_ptr> errors(parts);
  const auto run = [&](std::size_t part) {
    try {
      body(n * part / parts, n * (part + 1) / parts);
    } catch (...) {
      errors[part] = std::current_exception();
    }
  };
  std::vector<std::size_t> not_started;
  {
    std::vector<std::jthread> threads;
    threads.reserve(parts - 1);
    for (std::size_t part = 1; part < parts; ++part) {
      try {
        threads.emplace_back(run, part);
      } catch (const std::system_error&) {
        not_started.push_back(part);  // no thread to be had: the calling thread does this part
      }
    }
    run(0);
    for (const std::size_t part : not_started) run(part);
  }  // joined here
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);
}

}  // namespace servotwin::core
