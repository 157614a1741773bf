// Tiny synthetic datasets for the diagnosis tests: a 3 x 4 array, two short
// sessions, the simulated camera's 1 mm noise (calib/synthesize.h), and
// demo-baseline's true baseline, so that a diagnosis runs in seconds.
#pragma once

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>

#include "calib/dataset.h"
#include "calib/model_params.h"
#include "calib/synthesize.h"

namespace hj::testing_support {

inline nlohmann::json tiny_session_json(const std::string& name, const nlohmann::json& steps) {
  return {{"format", "hapticjam.session/1"},
          {"name", name},
          {"device", {{"rows", 3}, {"cols", 4}, {"cell_size_mm", 38.0}, {"max_pressure_kpa", 3.45}}},
          {"sensor", {{"kind", "depth camera"}, {"resolution_mm", 1.0}, {"accuracy_mm", 1.0}}},
          {"grid", {{"nx", 77}, {"ny", 58}, {"x0_mm", 0.0}, {"y0_mm", 0.0}, {"dx_mm", 2.0}, {"dy_mm", 2.0}}},
          {"steps", steps}};
}

// Two short sessions: an unjammed sweep through the levelling pressure
// (about 0.29 kPa) to 2 kPa, and two jammed cells raised to 1.5 kPa.
inline void write_tiny_sessions(const std::filesystem::path& dir) {
  using nlohmann::json;
  auto capture = [](int k) { return json{{"op", "capture"}, {"frame", "frames/00" + std::to_string(k) + ".csv"}}; };
  auto pressure = [](double kpa) { return json{{"op", "set_pressure"}, {"kpa", kpa}}; };
  const std::pair<std::string, json> sessions[] = {
      {"sweep", json::array({capture(0), pressure(0.2), capture(1), pressure(0.4), capture(2), pressure(1.0),
                             capture(3), pressure(2.0), capture(4)})},
      {"jammed", json::array({capture(0), pressure(0.6), {{"op", "jam"}, {"cell", {1, 1}}},
                              {{"op", "jam"}, {"cell", {0, 2}}}, capture(1), pressure(1.5), capture(2)})},
  };
  for (const auto& [name, steps] : sessions) {
    std::filesystem::create_directories(dir / name);
    std::ofstream(dir / name / "session.json") << tiny_session_json(name, steps).dump(1);
  }
}

// demo-baseline's true baseline (its README), not the paper's defaults.
inline ModelParams true_tiny_baseline() {
  ModelParams m;
  m.surface.mass_kg = 0.52;
  m.surface.spring_k = 58.0;
  m.surface.kappa_jam = 4.2;
  return m;
}

// root/sessions (the protocols) and root/data (the frames `truth` makes).
inline Dataset synthesize_tiny(const std::filesystem::path& root, const ModelParams& truth) {
  write_tiny_sessions(root / "sessions");
  synthesize_dataset(root / "sessions", root / "data", truth, SynthOptions{});
  return read_dataset(root / "data");
}

}  // namespace hj::testing_support
