// Depth-camera frames as CSV files (docs/session-format.md, "Frames"): ny
// lines of nx comma-separated heights in mm, line iy holding row iy; "nan"
// or an empty field marks a sample the camera did not see.
#pragma once

#include <Eigen/Core>
#include <filesystem>

namespace hj {

// Reads a frame into an (ny x nx) matrix of heights in mm, NaN = missing.
// Accepts "\r\n" line ends and a missing final newline.
// @throws SessionError naming the file (and the line and column) if it cannot
//         be read, holds a field that is not a number, "nan" or empty, holds
//         an infinite value, or is not ny lines of nx fields.
Eigen::MatrixXd read_frame_csv(const std::filesystem::path& path, int expected_ny, int expected_nx);

// Writes an (ny x nx) matrix of heights in mm, NaN as "nan", each number to
// 1e-4 mm with trailing zeros trimmed. Creates the parent folders; writes a
// temporary file beside `path` and renames it, so `path` is never left half
// written.
// @throws std::invalid_argument on an empty matrix or an infinite height,
//         std::runtime_error naming the file if it cannot be written.
void write_frame_csv(const std::filesystem::path& path, const Eigen::MatrixXd& heights_mm);

}  // namespace hj
