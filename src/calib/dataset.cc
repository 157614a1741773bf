#include "calib/dataset.h"

#include <algorithm>

#include "calib/frame_csv.h"

namespace hj {

namespace {

MeasuredSession read_measured_session(const std::filesystem::path& dir) {
  Session session = read_session(dir);
  return measured_session(std::move(session), [&](const Session& s, const SessionStep& step) {
    return read_frame_csv(s.frame_path(step), s.grid.ny, s.grid.nx);
  });
}

bool same_device(const SessionDevice& a, const SessionDevice& b) {
  return a.rows == b.rows && a.cols == b.cols && a.cell_size_mm == b.cell_size_mm;
}

}  // namespace

MeasuredSession measured_session(Session session,
                                 const std::function<Eigen::MatrixXd(const Session&, const SessionStep&)>& frame) {
  MeasuredSession out;
  out.session = std::move(session);
  const SessionDevice& device = out.session.device;
  double pressure_pa = 0.0;
  std::vector<bool> jammed(device.rows * device.cols, false);
  std::vector<std::pair<int, int>> pinned;
  for (const SessionStep& step : out.session.steps) {
    if (step.kind == SessionStep::Kind::kCapture) {
      out.captures.push_back({step.index, step.frame, step.label, frame(out.session, step), pressure_pa, jammed, pinned});
      continue;
    }
    const Action& a = step.action;
    const std::pair<int, int> node{a.a, a.b};
    switch (a.op) {
      case Action::Op::kSetPressure: pressure_pa = a.pressure_pa; break;
      case Action::Op::kJam: jammed[a.a * device.cols + a.b] = true; break;
      case Action::Op::kUnjam: jammed[a.a * device.cols + a.b] = false; break;
      case Action::Op::kPin:
        if (std::find(pinned.begin(), pinned.end(), node) == pinned.end()) pinned.push_back(node);
        break;
      case Action::Op::kUnpin: std::erase(pinned, node); break;
    }
  }
  return out;
}

int MeasuredCapture::jammed_count() const { return static_cast<int>(std::count(jammed.begin(), jammed.end(), true)); }

int Dataset::capture_count() const {
  int n = 0;
  for (const auto& s : sessions) n += static_cast<int>(s.captures.size());
  return n;
}

Dataset read_dataset(const std::filesystem::path& dir) {
  if (!std::filesystem::is_directory(dir)) throw SessionError(dir.string() + ": not a dataset folder");
  std::vector<std::filesystem::path> folders;
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    if (entry.is_directory() && std::filesystem::exists(entry.path() / "session.json")) folders.push_back(entry.path());
  if (folders.empty()) throw SessionError(dir.string() + ": no session folders (sub-folders with a session.json)");
  std::sort(folders.begin(), folders.end());
  Dataset out;
  out.dir = dir;
  for (const auto& folder : folders) {
    out.sessions.push_back(read_measured_session(folder));
    const Session& s = out.sessions.back().session;
    if (!same_device(s.device, out.device()))
      throw SessionError((folder / "session.json").string() + ": \"device\" differs from that of " +
                         out.sessions.front().session.name + "; a dataset holds sessions of one device");
  }
  return out;
}

Dataset select_sessions(const Dataset& dataset, const std::vector<std::string>& names, bool keep) {
  for (const auto& name : names) {
    const bool known = std::any_of(dataset.sessions.begin(), dataset.sessions.end(),
                                   [&](const MeasuredSession& s) { return s.session.name == name; });
    if (!known) {
      std::string all;
      for (const auto& s : dataset.sessions) all += (all.empty() ? "" : ", ") + s.session.name;
      throw SessionError(dataset.dir.string() + ": no session named \"" + name + "\"; sessions: " + all);
    }
  }
  Dataset out;
  out.dir = dataset.dir;
  for (const auto& s : dataset.sessions)
    if ((std::find(names.begin(), names.end(), s.session.name) != names.end()) == keep) out.sessions.push_back(s);
  return out;
}

Dataset sessions_up_to(const Dataset& dataset, const std::function<bool(const MeasuredCapture&)>& chosen) {
  Dataset out;
  out.dir = dataset.dir;
  for (const auto& s : dataset.sessions) {
    int last = -1;
    for (size_t c = 0; c < s.captures.size(); ++c)
      if (chosen(s.captures[c])) last = static_cast<int>(c);
    if (last < 0) continue;
    MeasuredSession head = s;
    head.captures.resize(last + 1);
    head.session.steps.resize(head.captures.back().step_index + 1);
    out.sessions.push_back(std::move(head));
  }
  return out;
}

}  // namespace hj
