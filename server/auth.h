// Who is calling and what they may do: bearer tokens from the `authorization`
// metadata ("Bearer TOKEN"), mapped to a name and a role by the auth file.
// Roles are ordered: preview < operator < admin.
//
// Auth file, one caller per line, '#' starts a comment:
//   NAME ROLE TOKEN
//   alice admin 3f9c...e1
//   cad-plugin preview 77ab...90
#pragma once

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace hj::server {

enum class Role { kPreview = 0, kOperator = 1, kAdmin = 2 };

const char* role_name(Role role);

struct Caller {
  std::string name;
  Role role = Role::kAdmin;
};

class Authenticator {
 public:
  // No auth file: every caller is "local" with every role (loopback only).
  Authenticator() = default;
  // @throws std::invalid_argument naming the file and line: not three fields,
  //         an unknown role, a repeated token or name, no caller at all.
  static Authenticator from_file(const std::filesystem::path& file);

  bool enabled() const { return enabled_; }
  // What the server should warn about (e.g. a token file others can read).
  const std::vector<std::string>& warnings() const { return warnings_; }

  // The caller for an `authorization` header value (empty if none was sent),
  // needing at least `role`.
  // @throws ServiceError UNAUTHENTICATED (no or unknown token),
  //         PERMISSION_DENIED (known caller without the role; names both).
  Caller authorize(const std::optional<std::string>& authorization, Role role, const std::string& action) const;

 private:
  const Caller* match_token(const std::string& token) const;

  bool enabled_ = false;
  std::map<std::string, Caller> by_token_;
  std::vector<std::string> warnings_;
};

}  // namespace hj::server
