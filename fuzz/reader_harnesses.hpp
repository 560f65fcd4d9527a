#pragma once
// Bodies of the reader fuzzers (issue 27 §5), shared by the libFuzzer targets fuzz/fuzz_<reader>.cpp
// (clang) and the replay test tests/io/test_reader_fuzz_replay.cpp (any compiler), so every corpus
// and regression input is checked in CI without clang.
//
// Contract for one input, for every reader: it either returns a value or throws core::InputError;
// any other exception, a crash, a hang or a leak is a finding. Where a writer exists, what was read
// is written and must read back (a reader must accept its own writer's output).

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <functional>
#include <sstream>
#include <string>
#include <string_view>

#include "servotwin/core/error.hpp"
#include "servotwin/io/controller_json.hpp"
#include "servotwin/io/excitation_csv.hpp"
#include "servotwin/io/frf_csv.hpp"
#include "servotwin/io/klipper_csv.hpp"
#include "servotwin/io/machine_json.hpp"
#include "servotwin/io/plant_json.hpp"
#include "servotwin/io/plant_model_json.hpp"
#include "servotwin/io/rapid_json.hpp"
#include "servotwin/io/shaper_json.hpp"
#include "servotwin/io/signal_csv.hpp"
#include "servotwin/io/trace_profile.hpp"
#include "servotwin/motion/gcode.hpp"
#include "servotwin/motion/interpolation.hpp"

namespace servotwin::fuzz {

/// Runs `read`: returns normally when it succeeds or rejects the input with core::InputError;
/// aborts, naming the exception, on anything else (what libFuzzer then reports with the input).
inline void expect_only_input_errors(const char* reader, const std::function<void()>& read) {
  try {
    read();
  } catch (const core::InputError&) {
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: unexpected exception: %s\n", reader, e.what());
    std::abort();
  } catch (...) {
    std::fprintf(stderr, "%s: unexpected non-standard exception\n", reader);
    std::abort();
  }
}

/// A writer's output that its reader refuses is a finding too.
[[noreturn]] inline void refused_own_output(const char* reader, const core::InputError& e) {
  std::fprintf(stderr, "%s: the writer's own output was refused: %s\n", reader, e.what());
  std::abort();
}

inline std::string_view as_text(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

inline void frf_csv_one_input(const std::uint8_t* data, std::size_t size) {
  expect_only_input_errors("frf_csv", [&] {
    std::istringstream in{std::string(as_text(data, size))};
    const core::FrequencyResponse r = io::read_frf_csv(in, "fuzz.csv");
    std::ostringstream out;
    io::write_frf_csv(out, r);
    std::istringstream back(out.str());
    try {
      if (io::read_frf_csv(back, "rewritten.csv").size() != r.size()) std::abort();
    } catch (const core::InputError& e) {
      refused_own_output("frf_csv", e);
    }
  });
}

inline void klipper_csv_one_input(const std::uint8_t* data, std::size_t size) {
  expect_only_input_errors("klipper_csv", [&] {
    std::istringstream in{std::string(as_text(data, size))};
    const shaping::Spectrum s = io::read_klipper_csv(in, "fuzz.csv");
    const std::size_t n = s.freq_hz.size();
    if (s.psd_x.size() != n || s.psd_y.size() != n || s.psd_z.size() != n || s.psd_sum.size() != n) std::abort();
  });
}

inline void signal_csv_one_input(const std::uint8_t* data, std::size_t size) {
  expect_only_input_errors("signal_csv", [&] {
    io::SignalReadOptions variants[2];
    variants[1].fs = 1000.0;
    for (const auto& options : variants) {
      std::istringstream in{std::string(as_text(data, size))};
      try {
        const io::SignalTable t = io::read_signal_csv(in, "fuzz.csv", options);
        if (!(t.ts > 0.0) || t.names.size() != t.columns.size()) std::abort();
        for (const auto& c : t.columns)
          if (c.size() != t.columns.front().size()) std::abort();
      } catch (const core::InputError&) {
      }
    }
  });
}

inline void excitation_csv_one_input(const std::uint8_t* data, std::size_t size) {
  expect_only_input_errors("excitation_csv", [&] {
    std::istringstream in{std::string(as_text(data, size))};
    (void)io::read_excitation_csv(in, "fuzz.csv");
  });
}

inline void axis_model_one_input(const std::uint8_t* data, std::size_t size) {
  expect_only_input_errors("axis_model", [&] { (void)io::parse_axis_model_json(as_text(data, size), "fuzz.json"); });
}

inline void normal_equations_one_input(const std::uint8_t* data, std::size_t size) {
  expect_only_input_errors("normal_equations", [&] {
    const rapid::NormalEquations ne = io::parse_normal_equations_json(as_text(data, size), "fuzz.json");
    std::vector<std::string> warnings;
    (void)rapid::RegressionProblem::from_normal_equations(ne, &warnings);
  });
}

inline void machine_one_input(const std::uint8_t* data, std::size_t size) {
  expect_only_input_errors("machine", [&] {
    const machine::MachineConfig m = io::parse_machine_json(as_text(data, size), "fuzz.json");
    try {
      (void)io::parse_machine_json(io::machine_to_json(m).dump(), "rewritten.json");
    } catch (const core::InputError& e) {
      refused_own_output("machine", e);
    }
  });
}

inline void plant_one_input(const std::uint8_t* data, std::size_t size) {
  expect_only_input_errors("plant", [&] {
    const machine::PlantConfig p = io::parse_plant_json(as_text(data, size), "fuzz.json");
    try {
      (void)io::parse_plant_json(io::plant_to_json(p).dump(), "rewritten.json");
    } catch (const core::InputError& e) {
      refused_own_output("plant", e);
    }
  });
}

inline void plant_model_one_input(const std::uint8_t* data, std::size_t size) {
  expect_only_input_errors("plant_model", [&] { (void)io::parse_plant_model_json(as_text(data, size), "fuzz.json"); });
}

inline void shaper_one_input(const std::uint8_t* data, std::size_t size) {
  expect_only_input_errors("shaper", [&] {
    const io::LoadedShaper s = io::parse_shaper_json(as_text(data, size), "fuzz.json");
    if (s.shaper.times.size() != s.shaper.amplitudes.size()) std::abort();
    try {
      const io::LoadedShaper back = io::parse_shaper_json(io::shaper_to_json(s.shaper, s.extras).dump(), "rewritten.json");
      if (back.shaper.times != s.shaper.times || back.shaper.amplitudes != s.shaper.amplitudes) std::abort();
    } catch (const core::InputError& e) {
      refused_own_output("shaper", e);
    }
  });
}

inline void controller_one_input(const std::uint8_t* data, std::size_t size) {
  expect_only_input_errors("controller", [&] { (void)io::parse_controller_json(as_text(data, size), "fuzz.json"); });
}

inline void trace_profile_one_input(const std::uint8_t* data, std::size_t size) {
  expect_only_input_errors("trace_profile", [&] {
    const io::TraceProfile p = io::parse_trace_profile(as_text(data, size), "fuzz.json");
    std::ostringstream out;
    io::write_trace_profile(out, p);
    try {
      (void)io::parse_trace_profile(out.str(), "rewritten.json");
    } catch (const core::InputError& e) {
      refused_own_output("trace_profile", e);
    }
  });
}

/// ISO and Heidenhain programs through the interpolator: a program the reader accepts is planned
/// and sampled (at most 200 000 samples, so that a long program is refused, not a hang).
inline void interpolation_one_input(const std::uint8_t* data, std::size_t size) {
  for (const motion::Dialect dialect : {motion::Dialect::Iso, motion::Dialect::Heidenhain}) {
    expect_only_input_errors("interpolation", [&] {
      motion::ParseOptions options;
      options.lenient = true;
      const motion::Program program = motion::parse_program(as_text(data, size), "fuzz.nc", options, dialect);
      motion::InterpolationLimits limits;
      limits.max_samples = 200'000;
      const motion::Trajectory t = motion::interpolate(program, limits);
      for (const auto& axis : t.positions)
        for (const double x : axis)
          if (!std::isfinite(x)) std::abort();
    });
  }
}

}  // namespace servotwin::fuzz
