// The thesis's loop closed (sections 3.4.1 and 4.3): identify X and Y of a virtual machine from a
// Table 3.2-style program, predict the tracking and contour errors of the circle and the diamond
// at 200 mm/s with 2000 mm/s^2, run the same toolpaths on the virtual machine and compare.
// docs/prediction-study.md reports these numbers (run test_validation to print them).
#include <gtest/gtest.h>

#include <cstdio>

#include "servotwin/motion/contour_programs.hpp"
#include "servotwin/vcnc/thesis_loop.hpp"
#include "validation_support.hpp"

namespace servotwin::validation {
namespace {

/// Models of X and Y identified from one Table 3.2-style program moving both (seed 7).
std::vector<vcnc::AxisModelSpec> identify_xy(const machine::MachineConfig& machine, rapid::Method method, bool refine) {
  const vcnc::IdentificationExperiment e = vcnc::run_identification_experiment(machine, 7);
  vcnc::IdentificationSettings settings;
  settings.method = method;
  settings.refine = refine;
  settings.shift_search = vcnc::ShiftSearch{};
  settings.solve.ga.generations = 100;
  return vcnc::model_specs(vcnc::identify_axes({{"identification", e.capture}}, settings));
}

struct ToolpathOutcome {
  double contour_rms_predicted = 0.0, contour_rms_actual = 0.0, contour_max_predicted = 0.0, contour_max_actual = 0.0;
  double contour_nrmse = 0.0;  // RMS(predicted - actual contour error) / RMS(actual - mean)
  double rms_ratio_error = 0.0;  // |RMS predicted / RMS actual - 1|
  double relative_rms_difference = 0.0;  // RMS(predicted - actual) / RMS(actual)
};

ToolpathOutcome run_toolpath(const machine::MachineConfig& machine, const std::vector<vcnc::AxisModelSpec>& models,
                             const motion::Program& program) {
  const vcnc::ContouringRun run = vcnc::contouring_run(machine, models, program);
  const vcnc::Prediction& p = run.prediction;
  const vcnc::MeasuredComparison& m = run.comparison;
  ToolpathOutcome o;
  const vcnc::PredictionScore* s = vcnc::overall_score(m, "contour");
  if (s == nullptr) {
    ADD_FAILURE() << "no contour score";
    return o;
  }
  o.contour_rms_predicted = s->metrics.rms_predicted;
  o.contour_rms_actual = s->metrics.rms_measured;
  o.contour_nrmse = s->metrics.nrmse;
  o.relative_rms_difference = s->metrics.rms_difference / s->metrics.rms_measured;
  for (std::size_t k = m.first; k < m.first + m.count; ++k) {
    o.contour_max_predicted = std::max(o.contour_max_predicted, std::abs(p.contour_error[k]));
    o.contour_max_actual = std::max(o.contour_max_actual, std::abs(m.contour_error[k]));
  }
  o.rms_ratio_error = std::abs(o.contour_rms_predicted / o.contour_rms_actual - 1.0);
  return o;
}

/// The target is 10 %. With the equation-error models PPI and PID meet it; the
/// sliding-mode loop's contour error (3 um RMS on a 40 mm circle) is predicted 19 % too high on the
/// circle and 28 % too low on the diamond. With the output-error refinement every preset meets it
/// (sliding mode: -0.8 % and -2.0 %); the sample-by-sample difference on the sliding-mode diamond
/// (1.6 um RMS contour error, 1 um encoder: quantization alone is q / sqrt(12) = 18 % of it) stays
/// above 10 % (docs/prediction-study.md).
struct Case {
  const char* machine;
  double rms_tolerance;         // |RMS(predicted contour error) / RMS(actual) - 1|, exact models
  double difference_tolerance;  // RMS(predicted - actual contour error) / RMS(actual), exact models
  double refined_difference_tolerance;  // the same with the refined models
};

class ContourPrediction : public ::testing::TestWithParam<Case> {};

TEST_P(ContourPrediction, CircleAndDiamondAt200MmPerSecond) {
  const machine::MachineConfig machine = machine::preset(GetParam().machine);
  motion::ContourProgramOptions o;
  o.center = vcnc::machine_start(machine);
  const motion::Program circle = motion::make_circle_program(o), diamond = motion::make_diamond_program(o);
  struct Variant {
    rapid::Method method;
    bool refine;
  };
  for (const Variant v : {Variant{rapid::Method::Exact, false}, Variant{rapid::Method::Ga, false}, Variant{rapid::Method::Exact, true}}) {
    const rapid::Method method = v.method;
    const auto models = identify_xy(machine, method, v.refine);
    for (const motion::Program* program : {&circle, &diamond}) {
      const ToolpathOutcome r = run_toolpath(machine, models, *program);
      std::printf("%s %s (%s%s): contour error RMS predicted %.2f um, actual %.2f um (%+.1f %%); max %.2f / %.2f um; "
                  "RMS(difference) / RMS(actual) %.3f\n",
                  machine.name.c_str(), program->name.c_str(), rapid::method_name(method), v.refine ? " + output error" : "", 1000 * r.contour_rms_predicted,
                  1000 * r.contour_rms_actual, 100 * (r.contour_rms_predicted / r.contour_rms_actual - 1.0),
                  1000 * r.contour_max_predicted, 1000 * r.contour_max_actual, r.relative_rms_difference);
      if (method == rapid::Method::Exact && !v.refine) {
        EXPECT_LT(r.rms_ratio_error, GetParam().rms_tolerance) << program->name;
        EXPECT_LT(r.relative_rms_difference, GetParam().difference_tolerance) << program->name;
      }
      if (v.refine) {
        EXPECT_LT(r.rms_ratio_error, 0.10) << program->name;
        EXPECT_LT(r.relative_rms_difference, GetParam().refined_difference_tolerance) << program->name;
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Presets, ContourPrediction,
                         ::testing::Values(Case{"fadal-ppi", 0.10, 0.10, 0.01}, Case{"fadal-pid", 0.10, 0.10, 0.07},
                                           Case{"fadal-smc", 0.35, 0.55, 0.27}),
                         [](const auto& param_info) {
                           std::string n = param_info.param.machine;
                           for (char& ch : n)
                             if (ch == '-') ch = '_';
                           return n;
                         });

}  // namespace
}  // namespace servotwin::validation
