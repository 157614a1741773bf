#include "auth.h"

#include <cstdint>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include "service_error.h"

namespace hj::server {

const char* role_name(Role role) {
  switch (role) {
    case Role::kPreview: return "preview";
    case Role::kOperator: return "operator";
    case Role::kAdmin: return "admin";
  }
  return "?";
}

namespace {

Role parse_role(const std::string& text, const std::string& where) {
  if (text == "preview") return Role::kPreview;
  if (text == "operator") return Role::kOperator;
  if (text == "admin") return Role::kAdmin;
  throw std::invalid_argument(where + ": unknown role \"" + text + "\" (preview, operator or admin)");
}

// Equal in time that depends on the lengths only, not on where the first
// difference is (a timing side channel would reveal a token byte by byte).
bool same_secret(const std::string& a, const std::string& b) {
  unsigned char difference = a.size() == b.size() ? 0 : 1;
  for (std::size_t i = 0; i < a.size(); ++i) difference |= std::uint8_t(a[i] ^ (i < b.size() ? b[i] : 0));
  return difference == 0;
}

}  // namespace

// Every token is compared, whether or not one matched already.
const Caller* Authenticator::match_token(const std::string& token) const {
  const Caller* found = nullptr;
  for (const auto& [known, caller] : by_token_)
    if (same_secret(token, known)) found = &caller;
  return found;
}

Authenticator Authenticator::from_file(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw std::invalid_argument("cannot read auth file \"" + file.string() + "\"");
  Authenticator auth;
  auth.enabled_ = true;
  std::set<std::string> names;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (const auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
    std::istringstream fields(line);
    std::string name, role, token, extra;
    if (!(fields >> name)) continue;
    const std::string where = "auth file \"" + file.string() + "\" line " + std::to_string(number);
    if (!(fields >> role >> token) || (fields >> extra))
      throw std::invalid_argument(where + ": expected NAME ROLE TOKEN");
    if (token.size() < 8) throw std::invalid_argument(where + ": token shorter than 8 characters");
    if (!names.insert(name).second) throw std::invalid_argument(where + ": caller \"" + name + "\" given twice");
    if (!auth.by_token_.emplace(token, Caller{name, parse_role(role, where)}).second)
      throw std::invalid_argument(where + ": token of \"" + name + "\" already belongs to another caller");
  }
  if (auth.by_token_.empty()) throw std::invalid_argument("auth file \"" + file.string() + "\" names no caller");
  using std::filesystem::perms;
  std::error_code error;
  const perms mode = std::filesystem::status(file, error).permissions();
  if (!error && (mode & (perms::group_read | perms::others_read)) != perms::none)
    auth.warnings_.push_back("auth file \"" + file.string() +
                             "\" is readable by other users (its tokens are secrets): chmod 600 it");
  return auth;
}

Caller Authenticator::authorize(const std::optional<std::string>& authorization, Role role,
                                const std::string& action) const {
  if (!enabled_) return Caller{"local", Role::kAdmin};
  const std::string prefix = "Bearer ";
  if (!authorization || authorization->rfind(prefix, 0) != 0)
    throw ServiceError(grpc::StatusCode::UNAUTHENTICATED,
                       "no bearer token: send metadata \"authorization: Bearer TOKEN\"");
  const Caller* found = match_token(authorization->substr(prefix.size()));
  if (found == nullptr) throw ServiceError(grpc::StatusCode::UNAUTHENTICATED, "unknown bearer token");
  const Caller& caller = *found;
  if (caller.role < role)
    throw ServiceError(grpc::StatusCode::PERMISSION_DENIED,
                       "caller \"" + caller.name + "\" has role " + role_name(caller.role) + "; " + action +
                           " needs " + role_name(role));
  return caller;
}

}  // namespace hj::server
