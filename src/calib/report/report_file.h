// Writing a report's files: bytes to a path, its folders made as needed.
#pragma once

#include <filesystem>
#include <string>

namespace hj {

// std::runtime_error naming the file if it cannot be written.
void write_file(const std::filesystem::path& path, const std::string& bytes);

// The RFC 4648 base64 of bytes (for data: URIs in a self-contained page).
std::string base64(const std::string& bytes);

}  // namespace hj
