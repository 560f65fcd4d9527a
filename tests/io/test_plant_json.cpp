// Plant JSON ("servotwin.plant/1"): the documented shapes parse to the expected configuration,
// every preset round-trips, and each bad input is a core::InputError naming file and field.

#include <gtest/gtest.h>

#include <string>

#include "servotwin/core/error.hpp"
#include "servotwin/io/plant_json.hpp"
#include "servotwin/machine/flexible_presets.hpp"

namespace servotwin::io {
namespace {

const char* kTwoMass = R"({"format": "servotwin.plant/1", "type": "two-mass",
  "motor_inertia": 0.0048, "load_inertia": 0.0051, "stiffness": 564.0, "damping": 0.068,
  "motor_viscous": 2e-4, "load_viscous": 1e-4, "coulomb": 0.01, "backlash": 0.001,
  "noise_std": 0.01, "ts": 0.000125})";

// Replaces `from` (which must occur) in the two-mass document.
std::string two_mass_with(const std::string& from, const std::string& to) {
  std::string text = kTwoMass;
  const auto pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  return text.replace(pos, from.size(), to);
}

// The field a parse error names (or "<accepted>"); also checks that the file is named.
std::string error_field(const std::string& text) {
  try {
    (void)parse_plant_json(text, "bench.json");
  } catch (const core::InputError& e) {
    EXPECT_EQ(e.where().file, "bench.json");
    EXPECT_NE(std::string(e.what()).find("bench.json"), std::string::npos);
    return e.where().field;
  }
  return "<accepted>";
}

TEST(PlantJson, TwoMassShapeParses) {
  const auto plant = parse_plant_json(kTwoMass, "dir/bench.json");
  EXPECT_EQ(plant.name, "bench");
  const auto& c = std::get<machine::MassChain>(plant.model);
  ASSERT_EQ(c.masses(), 2U);
  EXPECT_EQ(c.inertia[0], 0.0048);
  EXPECT_EQ(c.inertia[1], 0.0051);
  EXPECT_EQ(c.stiffness[0], 564.0);
  EXPECT_EQ(c.damping_of(0), 0.068);
  EXPECT_EQ(c.viscous_of(0), 2e-4);
  EXPECT_EQ(c.viscous_of(1), 1e-4);
  EXPECT_EQ(c.friction_of(1).coulomb, 0.01);  // "coulomb" is the load's level
  EXPECT_EQ(c.friction_of(1).static_level(), 0.01);
  EXPECT_FALSE(c.friction_of(0).active());
  EXPECT_EQ(c.backlash_of(0), 0.001);
  EXPECT_EQ(plant.settings.noise_std, 0.01);
  EXPECT_EQ(plant.settings.ts, 0.000125);
  EXPECT_EQ(plant.settings.output, machine::PlantOutput::MotorVelocity);
}

TEST(PlantJson, OptionalFieldsParse) {
  const auto plant = parse_plant_json(
      two_mass_with(R"("ts": 0.000125)", R"("ts": 0.000125, "stiction": 0.02, "stick_band": 0.003,
        "motor_coulomb": 0.05, "motor_stiction": 0.07, "current_lag": 2e-4, "delay_samples": 2,
        "quantization": 1e-5, "seed": 18446744073709551615, "output": "load_position", "substeps": 16)"),
      "p.json");
  const auto& c = std::get<machine::MassChain>(plant.model);
  EXPECT_EQ(c.friction_of(1).static_level(), 0.02);
  EXPECT_EQ(c.friction_of(1).stick_band, 0.003);
  EXPECT_EQ(c.friction_of(0).coulomb, 0.05);
  EXPECT_EQ(c.friction_of(0).static_level(), 0.07);
  EXPECT_EQ(plant.settings.current_lag, 2e-4);
  EXPECT_EQ(plant.settings.delay_samples, 2);
  EXPECT_EQ(plant.settings.quantization, 1e-5);
  EXPECT_EQ(plant.settings.seed, 18446744073709551615ULL);
  EXPECT_EQ(plant.settings.output, machine::PlantOutput::LoadPosition);
  EXPECT_EQ(plant.settings.substeps, 16);
}

TEST(PlantJson, MassChainAndTransferFunctionParse) {
  const auto chain = parse_plant_json(R"({"format": "servotwin.plant/1", "type": "mass-chain",
      "inertias": [1, 0.5, 2], "stiffnesses": [100, 200], "dampings": [0.1, 0.2],
      "viscous": [0.01, 0, 0.02], "coulomb": [0.1, 0, 0.3], "stiction": [0.2, 0, 0.3],
      "stick_band": 0.01, "backlash": [0, 0.002], "noise_std": 0, "ts": 0.001})",
                                      "chain.json");
  const auto& c = std::get<machine::MassChain>(chain.model);
  ASSERT_EQ(c.masses(), 3U);
  EXPECT_EQ(c.stiffness[1], 200.0);
  EXPECT_EQ(c.friction_of(0).static_level(), 0.2);
  EXPECT_EQ(c.friction_of(2).stick_band, 0.01);
  EXPECT_EQ(c.backlash_of(1), 0.002);
  const auto tf = parse_plant_json(R"({"format": "servotwin.plant/1", "type": "transfer-function",
      "num": [0.5, 0.06, 0.5], "den": [1, 1.1, 9.18, 1.8], "noise_std": 0.1, "ts": 0.01})",
                                   "tf.json");
  const auto& model = std::get<machine::TransferFunctionModel>(tf.model);
  EXPECT_EQ(model.tf.den().degree(), 3);
  EXPECT_EQ(model.tf.num().coefficients()[1], 0.06);
}

// The flexible-frame type is read as eq. 7.172 (machine::flexible_frame_transfer_function): the
// C7.19 document gives the preset's model.
const char* kFrame = R"({"format": "servotwin.plant/1", "type": "flexible-frame",
  "frame_mass": 70, "frame_stiffness": 4500, "frame_damping": 0.01, "stator_mass": 0.2,
  "mount_stiffness": 5, "mount_damping": 0.02, "rotor_mass": 0.1, "coupling_stiffness": 0.1,
  "coupling_damping": 0.01, "load_mass": 0.2, "noise_std": 0, "ts": 0.01})";

std::string frame_with(const std::string& from, const std::string& to) {
  std::string text = kFrame;
  const auto pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  return text.replace(pos, from.size(), to);
}

TEST(PlantJson, FlexibleFrameIsReadAsItsRotorVelocityTransferFunction) {
  const machine::PlantConfig frame = parse_plant_json(kFrame, "frame.json");
  const auto& model = std::get<machine::TransferFunctionModel>(frame.model);
  const machine::PlantConfig preset_config = machine::flexible_preset("c7.19-frame");
  const auto& preset = std::get<machine::TransferFunctionModel>(preset_config.model);
  EXPECT_EQ(model.tf.num(), preset.tf.num());
  EXPECT_EQ(model.tf.den(), preset.tf.den());
  EXPECT_EQ(model.tf.den().degree(), 7);
  ASSERT_TRUE(frame.frame.has_value());  // kept for the frame-sequence test
  EXPECT_EQ(frame.frame->load_mass, 0.2);
  EXPECT_EQ(frame.frame->mount_stiffness, 5.0);
  EXPECT_EQ(plant_to_json(frame)["type"], "flexible-frame");
  // A position output adds the integrator.
  const machine::PlantConfig position =
      parse_plant_json(frame_with(R"("ts": 0.01)", R"("ts": 0.01, "output": "motor_position")"), "frame.json");
  const auto& tf = std::get<machine::TransferFunctionModel>(position.model).tf;
  EXPECT_EQ(tf.den().degree(), 8);
  EXPECT_EQ(tf.den().coefficients().back(), 0.0);
}

TEST(PlantJson, BadFlexibleFrameNamesTheField) {
  EXPECT_EQ(error_field(frame_with(R"("load_mass": 0.2)", R"("load_mass": 0)")), "load_mass");
  EXPECT_EQ(error_field(frame_with(R"("mount_damping": 0.02)", R"("mount_damping": -1)")), "mount_damping");
  EXPECT_EQ(error_field(frame_with(R"("frame_mass": 70,)", "")), "frame_mass");
  EXPECT_EQ(error_field(frame_with(R"("ts": 0.01)", R"("ts": 0.01, "output": "load_velocity")")), "output");
  EXPECT_EQ(error_field(frame_with(R"("ts": 0.01)", R"("ts": 0.01, "inertias": [1])")), "inertias");
}

TEST(PlantJson, EveryPresetRoundTrips) {
  for (const auto& name : machine::flexible_preset_names()) {
    const auto preset = machine::flexible_preset(name);
    const auto json = plant_to_json(preset);
    const auto back = parse_plant_json(json.dump(), name + ".json");
    EXPECT_EQ(plant_to_json(back), json) << name;
    EXPECT_EQ(back.name, name);
    // The same linear model and settings.
    const machine::FlexiblePlant a(preset), b(back);
    for (double w : {0.3, 3.0, 300.0})
      EXPECT_EQ(a.transfer_function().frequency_response(w), b.transfer_function().frequency_response(w)) << name;
  }
}

TEST(PlantJson, ChainWithPerMassBandsIsWrittenAsMassChain) {
  machine::PlantConfig p;
  machine::MassChain c = machine::two_mass(1.0, 2.0, 30.0, 0.1);
  c.friction = {machine::KarnoppFriction{0.1, 0.2, 0.01}, machine::KarnoppFriction{0.1, std::nullopt, 0.02}};
  p.model = c;
  p.settings.ts = 0.001;
  const auto json = plant_to_json(p);
  EXPECT_EQ(json["type"], "mass-chain");
  const auto back = parse_plant_json(json.dump(), "x.json");
  EXPECT_EQ(std::get<machine::MassChain>(back.model).friction_of(1).stick_band, 0.02);
  EXPECT_EQ(plant_to_json(back)["stick_band"], json["stick_band"]);
}

TEST(PlantJson, BadInputNamesFileAndField) {
  EXPECT_EQ(error_field(two_mass_with("servotwin.plant/1", "servotwin.plant/2")), "format");
  EXPECT_EQ(error_field(two_mass_with("servotwin.plant/1", "servotwin.machine/1")), "format");
  EXPECT_EQ(error_field(two_mass_with(R"("stiffness": 564.0,)", "")), "stiffness");
  EXPECT_EQ(error_field(two_mass_with(R"("noise_std": 0.01,)", "")), "noise_std");
  EXPECT_EQ(error_field(two_mass_with(R"("damping": 0.068)", R"("damping": -0.068)")), "damping");
  EXPECT_EQ(error_field(two_mass_with(R"("coulomb": 0.01)", R"("coulomb": -1)")), "coulomb");
  EXPECT_EQ(error_field(two_mass_with(R"("motor_inertia": 0.0048)", R"("motor_inertia": 0)")), "motor_inertia");
  EXPECT_EQ(error_field(two_mass_with(R"("load_inertia": 0.0051)", R"("load_inertia": -2)")), "load_inertia");
  EXPECT_EQ(error_field(two_mass_with(R"("ts": 0.000125)", R"("ts": 0)")), "ts");
  // A number beyond the double range is rejected by the JSON parser itself (no field yet).
  EXPECT_EQ(error_field(two_mass_with(R"("ts": 0.000125)", R"("ts": 1e999)")), "");
  EXPECT_EQ(error_field(two_mass_with(R"("ts": 0.000125)", R"("ts": "fast")")), "ts");
  EXPECT_EQ(error_field(two_mass_with(R"("backlash": 0.001)", R"("backlash": 0.001, "colomb": 1)")), "colomb");
  EXPECT_EQ(error_field(two_mass_with(R"("backlash": 0.001)", R"("backlash": 0.001, "stiction": 0.001)")),
            "stiction");  // below coulomb
  EXPECT_EQ(error_field(two_mass_with(R"("backlash": 0.001)", R"("backlash": 0.001, "output": "torque")")), "output");
  EXPECT_EQ(error_field(two_mass_with(R"("backlash": 0.001)", R"("backlash": 0.001, "delay_samples": 1.5)")),
            "delay_samples");
  EXPECT_EQ(error_field(two_mass_with(R"("backlash": 0.001)", R"("backlash": 0.001, "seed": -3)")), "seed");
  EXPECT_EQ(error_field(two_mass_with(R"("two-mass")", R"("three-mass")")), "type");
  const std::string chain = R"({"format": "servotwin.plant/1", "type": "mass-chain", "inertias": [1, X, 2],
      "stiffnesses": [100, 200], "dampings": [0.1, 0.2], "noise_std": 0, "ts": 0.001})";
  const auto chain_with = [&](const std::string& x) { return std::string(chain).replace(chain.find('X'), 1, x); };
  EXPECT_EQ(error_field(chain_with("0.5")), "<accepted>");
  EXPECT_EQ(error_field(chain_with("-0.5")), "inertias[1]");
  EXPECT_EQ(error_field(chain_with("null")), "inertias[1]");
  EXPECT_EQ(error_field(chain_with("0.5, 3")), "stiffnesses");  // 4 masses need 3 shafts
  const std::string tf = R"({"format": "servotwin.plant/1", "type": "transfer-function",
      "num": [1], "den": D, "noise_std": 0, "ts": 0.01})";
  const auto tf_with = [&](const std::string& d) { return std::string(tf).replace(tf.find('D'), 1, d); };
  EXPECT_EQ(error_field(tf_with("[1, 2, 1]")), "<accepted>");
  EXPECT_EQ(error_field(tf_with("[1, -2, 1]")), "den");  // unstable
  EXPECT_EQ(error_field(tf_with("[0, 0]")), "den");
  EXPECT_EQ(error_field(tf_with("[]")), "den");
}

TEST(PlantJson, SyntaxErrorsAndNaNGiveLineAndColumn) {
  try {
    (void)parse_plant_json("{\"format\": \"servotwin.plant/1\",\n \"ts\": NaN}", "bad.json");
    FAIL();
  } catch (const core::InputError& e) {
    EXPECT_EQ(e.where().file, "bad.json");
    EXPECT_EQ(e.where().line, 2U);
  }
}

TEST(PlantJson, LoadPlantAcceptsPresetNamesAndRejectsUnknownOnes) {
  EXPECT_EQ(load_plant("rfid-demo").name, "rfid-demo");
  try {
    (void)load_plant("/nonexistent/plant.json");
    FAIL();
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("testbed-1"), std::string::npos);
  }
}

}  // namespace
}  // namespace servotwin::io
