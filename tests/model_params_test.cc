// The params file: round trip, defaults, and errors that name the key.
#include <gtest/gtest.h>

#include "calib/model_params.h"
#include "expect_error.h"
#include "scratch_dir.h"

namespace hj {
namespace {
using testing_support::expect_error;
using testing_support::ScratchDir;

const SurfaceParameters kDefaults = SurfaceParameters::paper_defaults({3, 4, 0.038, 4});

TEST(ModelParams, MissingSurfaceFieldsKeepTheirDefaults) {
  const auto p = parse_model_params(nlohmann::json::parse(R"({"surface": {"spring_k": 58}})"), kDefaults, "p.json");
  EXPECT_EQ(p.surface.spring_k, 58.0);
  EXPECT_EQ(p.surface.mass_kg, kDefaults.mass_kg);
  EXPECT_TRUE(p.effects.empty());
}

TEST(ModelParams, RoundTripThroughAFile) {
  ModelParams p;
  p.surface = kDefaults;
  p.surface.mass_kg = 0.52;
  p.surface.kappa_jam = 4.2;
  ScratchDir dir("model_params");
  const auto path = dir.path / "sub" / "params.json";
  write_model_params(path, p, {{"r2", 0.99}});
  const auto back = read_model_params(path, SurfaceParameters{});
  EXPECT_EQ(back.surface.mass_kg, 0.52);
  EXPECT_EQ(back.surface.kappa_jam, 4.2);
  EXPECT_EQ(back.surface.spring_k, kDefaults.spring_k);
}

TEST(ModelParams, ErrorsNameTheFileAndKey) {
  using nlohmann::json;
  const auto parse = [](const char* text) { (void)parse_model_params(json::parse(text), kDefaults, "p.json"); };
  expect_error<ParamsError>([&] { parse("[1]"); }, {"p.json", "object"});
  expect_error<ParamsError>([&] { parse(R"({"surface": {"spring": 1}})"); }, {"p.json", "surface.spring", "spring_k"});
  expect_error<ParamsError>([&] { parse(R"({"surface": {"spring_k": "x"}})"); }, {"surface.spring_k", "number"});
  expect_error<ParamsError>([&] { parse(R"({"surface": {"mass_kg": -1}})"); }, {"surface", "mass_kg"});
  expect_error<ParamsError>([&] { parse(R"({"effects": {"no-such": {}}})"); }, {"effects.no-such", "unknown effect"});
  expect_error<ParamsError>([&] { parse(R"({"effects": {"gravity": {}}})"); }, {"effects.gravity", "baseline"});
  expect_error<ParamsError>([&] { parse(R"({"format": "other/2"})"); }, {"format", "hapticjam.params/1"});
  ScratchDir dir("model_params_bad");
  expect_error<ParamsError>([&] { (void)read_model_params(dir.path / "none.json", kDefaults); },
                            {"none.json", "cannot open"});
}

}  // namespace
}  // namespace hj
