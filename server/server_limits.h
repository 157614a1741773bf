// Bounds on what one request may ask of the server, so an absurd request is
// refused with INVALID_ARGUMENT naming the limit instead of exhausting memory
// or time, and the transport's bounds (gRPC's resource quota, streams,
// keepalive). server/README.md lists them with their flags.
#pragma once

#include <algorithm>
#include <chrono>

namespace hj::server {

struct ServerLimits {
  // gRPC's receive limit (default 4 MiB is too small for meshes and DEMs).
  int max_message_bytes = 64 << 20;
  // Values in a goal image or table, or in a mesh's top view.
  long max_goal_pixels = 16'000'000;
  // A mesh's top view, pixels along its longer side.
  int max_view_resolution = 2048;
  // The array: cells per side, segments per cell edge, mesh points.
  int max_array_side_cells = 64;
  int max_segments = 16;
  int max_mesh_points = 200'000;
  // Steps in one device job.
  int max_job_steps = 100'000;
  // An uploaded dataset (CalibrationService): sessions, and files in all.
  int max_upload_sessions = 1'000;
  long max_upload_files = 100'000;

  // The longest a call may run whatever deadline its caller set (zero = no
  // bound): Plan and Preview (--max-plan-seconds); Compare, Fit and Diagnose
  // (--max-calibration-seconds). Past it the call ends DEADLINE_EXCEEDED and its work stops.
  std::chrono::milliseconds max_plan_time = std::chrono::minutes(30);
  std::chrono::milliseconds max_calibration_time = std::chrono::hours(6);
  // Cores one Compare, Fit or Diagnose may use (--calibration-threads; 0 = all).
  int calibration_threads = 0;
  // A device job's name, in bytes (--max-job-name-bytes).
  int max_job_name_bytes = 200;
  // WatchQueue streams open at once (each holds a server thread), and the
  // finished jobs one may ask to list (--max-watchers).
  int max_watchers = 32;
  int max_recent_finished = 1'000;

  // gRPC: threads the server may use for calls (ResourceQuota, --max-threads),
  // concurrent calls on one connection (--max-streams), and keepalive: the
  // server pings an idle connection every keepalive_time and drops it if no
  // answer comes within keepalive_timeout (--keepalive-seconds; a client may
  // ping no more often than every 10 s).
  int max_threads = 256;
  int max_concurrent_streams = 100;
  std::chrono::milliseconds keepalive_time = std::chrono::seconds(60);
  std::chrono::milliseconds keepalive_timeout = std::chrono::seconds(20);
};

// The threads one calibration call runs on: the caller's request (0 = as
// many as allowed), at most the operator's limit and the machine's cores.
inline int calibration_thread_count(int requested, const ServerLimits& limits, int cores) {
  const int allowed = limits.calibration_threads > 0 ? std::min(limits.calibration_threads, cores) : cores;
  return requested > 0 ? std::min(requested, allowed) : allowed;
}

}  // namespace hj::server
