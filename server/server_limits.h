// Bounds on what one request may ask of the server, so an absurd request is
// refused with INVALID_ARGUMENT naming the limit instead of exhausting memory
// or time. server/README.md lists them.
#pragma once

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
};

}  // namespace hj::server
