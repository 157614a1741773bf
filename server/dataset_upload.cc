#include "dataset_upload.h"

#include <stdlib.h>

#include <fstream>
#include <set>

#include "service_error.h"

namespace hj::server {

namespace v1 = ::hapticjam::v1;
namespace fs = std::filesystem;

namespace {

[[noreturn]] void refuse(const std::string& message) {
  throw ServiceError(grpc::StatusCode::INVALID_ARGUMENT, message);
}

// A folder name: one path component, not "." or "..".
void check_name(const std::string& name, const std::string& what) {
  if (name.empty()) refuse(what + ": empty name");
  if (name == "." || name == ".." || name.find_first_of(std::string("/\\\0", 3)) != std::string::npos)
    refuse(what + " \"" + name + "\": not a plain folder name");
}

// A path below the session folder: relative, no "." / ".." / empty parts.
fs::path checked_relative(const std::string& path, const std::string& what) {
  if (path.empty() || path.front() == '/' || path.find('\0') != std::string::npos || path.find('\\') != std::string::npos)
    refuse(what + ": \"" + path + "\" is not a relative path inside the session folder");
  const fs::path p(path);
  for (const auto& part : p)
    if (part.empty() || part == "." || part == "..")
      refuse(what + ": \"" + path + "\" is not a relative path inside the session folder");
  return p;
}

void write_file(const fs::path& path, const std::string& content) {
  fs::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary);
  out.write(content.data(), static_cast<std::streamsize>(content.size()));
  if (!out) throw std::runtime_error("cannot write the uploaded file " + path.string() + " on the server");
}

// A private folder under the system's temporary folder, removed on exit.
class ScratchFolder {
 public:
  ScratchFolder() {
    std::string pattern = (fs::temp_directory_path() / "hj-upload-XXXXXX").string();
    if (!::mkdtemp(pattern.data())) throw std::runtime_error("cannot create a folder for the uploaded dataset");
    path_ = pattern;
  }
  ~ScratchFolder() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  ScratchFolder(const ScratchFolder&) = delete;
  ScratchFolder& operator=(const ScratchFolder&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

// `text` with every occurrence of `prefix` removed.
std::string without(std::string text, const std::string& prefix) {
  for (size_t at; (at = text.find(prefix)) != std::string::npos;) text.erase(at, prefix.size());
  return text;
}

}  // namespace

Dataset dataset_from_upload(const v1::UploadedDataset& upload, const ServerLimits& limits) {
  const std::string name = upload.name().empty() ? "dataset" : upload.name();
  check_name(name, "dataset.name");
  if (upload.sessions().empty()) refuse("dataset \"" + name + "\": no session uploaded");
  if (upload.sessions_size() > limits.max_upload_sessions)
    refuse("dataset \"" + name + "\": " + std::to_string(upload.sessions_size()) + " sessions, more than the limit of " +
           std::to_string(limits.max_upload_sessions));
  long files = 0;
  for (const auto& s : upload.sessions()) files += s.files_size();
  if (files > limits.max_upload_files)
    refuse("dataset \"" + name + "\": " + std::to_string(files) + " files, more than the limit of " +
           std::to_string(limits.max_upload_files));

  ScratchFolder scratch;
  const fs::path root = scratch.path() / name;
  std::set<std::string> session_names;
  for (int i = 0; i < upload.sessions_size(); ++i) {
    const v1::UploadedSession& s = upload.sessions(i);
    const std::string where = "dataset.sessions[" + std::to_string(i) + "]";
    check_name(s.name(), where + ".name");
    if (!session_names.insert(s.name()).second) refuse(where + ": session \"" + s.name() + "\" uploaded twice");
    const fs::path dir = root / s.name();
    fs::create_directories(dir);
    write_file(dir / "session.json", s.session_json());
    std::set<fs::path> paths{"session.json"};
    for (int f = 0; f < s.files_size(); ++f) {
      const std::string file_where = name + "/" + s.name() + " files[" + std::to_string(f) + "]";
      const fs::path relative = checked_relative(s.files(f).path(), file_where);
      if (!paths.insert(relative.lexically_normal()).second)
        refuse(file_where + ": \"" + s.files(f).path() + "\" uploaded twice (or is session.json)");
      try {
        write_file(dir / relative, s.files(f).content());
      } catch (const fs::filesystem_error&) {
        // e.g. "frames" uploaded as a file and "frames/000.csv" too
        refuse(file_where + ": \"" + s.files(f).path() + "\" cannot be stored: one of its folders is an uploaded file");
      }
    }
  }
  try {
    Dataset dataset = read_dataset(root);
    // The scratch folder goes; the frames are in memory. Name things as
    // the client did.
    dataset.dir = name;
    for (auto& m : dataset.sessions) m.session.dir = fs::path(name) / m.session.dir.filename();
    return dataset;
  } catch (const SessionError& e) {
    refuse(without(e.what(), scratch.path().string() + "/"));
  }
}

}  // namespace hj::server
