#include "server_options.h"

#include <chrono>
#include <stdexcept>
#include <thread>

namespace hj::server {

const char* const kServerUsage =
    "usage: hapticjam-server --listen HOST:PORT [--device HOST:PORT|SERIAL] [--workers N]\n"
    "                        [--auth FILE] [--db FILE] [--tls-cert F --tls-key F] [--trusted-network]\n"
    "                        [--map NAME=FILE ...] [--queue-size N] [--device-queue-size N]\n"
    "                        [--cache-size N] [--max-message-mib N] [--http HOST:PORT]\n"
    "                        [--keep-jobs N] [--keep-days N] [per-call and transport limits]\n"
    "The hapticjam gRPC server (proto/hapticjam/v1): planning on a pool of simulator\n"
    "workers, and a persistent queue of jobs for the attached array.\n"
    "  --listen HOST:PORT      address to serve on; port 0 picks a free port (printed).\n"
    "                          Without --auth only loopback (127.0.0.1, localhost, [::1]).\n"
    "  --device ENDPOINT       the array's controller: HOST:PORT (TCP) or a serial device\n"
    "                          such as /dev/ttyUSB0. Without it the device service answers\n"
    "                          FAILED_PRECONDITION.\n"
    "  --workers N             planning workers (default: one per core)\n"
    "  --auth FILE             bearer tokens and roles, one caller per line: NAME ROLE TOKEN,\n"
    "                          ROLE preview | operator | admin (server/README.md)\n"
    "  --db FILE               the device queue's SQLite database (default hapticjam-queue.db)\n"
    "  --tls-cert F --tls-key F  serve TLS with this PEM certificate chain and key\n"
    "  --trusted-network       allow --auth on a non-loopback address without TLS (the\n"
    "                          tokens then cross the network in the clear)\n"
    "  --map NAME=FILE         a goal map (DEM table, image) clients can name and crop;\n"
    "                          repeatable\n"
    "  --queue-size N          planning requests that may wait for a worker (default 16);\n"
    "                          one more is refused with RESOURCE_EXHAUSTED\n"
    "  --device-queue-size N   device jobs that may wait (default 64)\n"
    "  --cache-size N          planning results kept for repeated requests (default 256, 0 = off)\n"
    "  --max-message-mib N     largest request accepted (default 64 MiB)\n"
    "  --http HOST:PORT        also serve the web viewer there (clients/web, docs/web.md):\n"
    "                          a gateway process over this server's gRPC API; loopback\n"
    "                          only without --auth; port 0 picks one (printed)\n"
    "  --keep-jobs N           finished device jobs (with their captures) kept, newest first\n"
    "                          (default 1000, 0 = no bound)\n"
    "  --keep-days N           finished device jobs older than N days are deleted (default 30,\n"
    "                          0 = no bound)\n"
    "Per-call and transport limits (server/README.md, docs/safety.md):\n"
    "  --max-plan-seconds N    longest Plan or Preview, whatever the caller's deadline\n"
    "                          (default 1800, 0 = no bound); past it DEADLINE_EXCEEDED\n"
    "  --max-calibration-seconds N  longest Compare, Fit or Diagnose (default 21600, 0 = no bound)\n"
    "  --calibration-threads N cores one Compare, Fit or Diagnose may use (default 0 = all)\n"
    "  --max-job-name-bytes N  longest device job name (default 200)\n"
    "  --max-watchers N        WatchQueue streams open at once (default 32)\n"
    "  --max-threads N         threads gRPC may use for calls (resource quota, default 256)\n"
    "  --max-streams N         concurrent calls on one connection (default 100)\n"
    "  --keepalive-seconds N   ping an idle connection this often, drop it after 20 s\n"
    "                          without an answer (default 60)\n"
    "  --help                  this text\n"
    "Logs: one JSON object per line on stderr. SIGINT/SIGTERM shut down cleanly.\n";

namespace {

int parse_count(const std::string& flag, const std::string& text, int lo, int hi) {
  size_t used = 0;
  long value = 0;
  try {
    value = std::stol(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || text.empty() || value < lo || value > hi)
    throw std::invalid_argument(flag + " needs a whole number in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                                "], got \"" + text + "\"");
  return int(value);
}

// The per-call and transport limits' flags; false if `flag` is none of them.
bool parse_limit_flag(const std::string& flag, const std::string& v, ServerLimits& limits) {
  using std::chrono::seconds;
  if (flag == "--max-plan-seconds") limits.max_plan_time = seconds(parse_count(flag, v, 0, 1'000'000));
  else if (flag == "--max-calibration-seconds") limits.max_calibration_time = seconds(parse_count(flag, v, 0, 10'000'000));
  else if (flag == "--calibration-threads") limits.calibration_threads = parse_count(flag, v, 0, 1024);
  else if (flag == "--max-job-name-bytes") limits.max_job_name_bytes = parse_count(flag, v, 1, 65'536);
  else if (flag == "--max-watchers") limits.max_watchers = parse_count(flag, v, 1, 10'000);
  else if (flag == "--max-threads") limits.max_threads = parse_count(flag, v, 8, 100'000);
  else if (flag == "--max-streams") limits.max_concurrent_streams = parse_count(flag, v, 1, 100'000);
  else if (flag == "--keepalive-seconds") limits.keepalive_time = seconds(parse_count(flag, v, 10, 86'400));
  else return false;
  return true;
}

}  // namespace

bool is_loopback_listen(const std::string& listen) {
  const auto colon = listen.rfind(':');
  const std::string host = colon == std::string::npos ? listen : listen.substr(0, colon);
  return host == "127.0.0.1" || host == "localhost" || host == "[::1]" || host == "::1";
}

ServerOptions parse_server_args(const std::vector<std::string>& args, bool* help) {
  ServerOptions out;
  *help = false;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--help" || a == "-h") {
      *help = true;
      return out;
    }
    if (a.rfind("--", 0) != 0) throw std::invalid_argument("unexpected argument \"" + a + "\"");
    if (a == "--trusted-network") {
      out.trusted_network = true;
      continue;
    }
    if (i + 1 >= args.size()) throw std::invalid_argument(a + " needs a value");
    const std::string& v = args[++i];
    if (a == "--listen") out.listen = v;
    else if (a == "--device") out.device = v;
    else if (a == "--workers") out.workers = parse_count(a, v, 1, 1024);
    else if (a == "--auth") out.auth_file = v;
    else if (a == "--db") out.db_file = v;
    else if (a == "--tls-cert") out.tls_cert = v;
    else if (a == "--tls-key") out.tls_key = v;
    else if (a == "--map") {
      const auto eq = v.find('=');
      if (eq == std::string::npos || eq == 0 || eq + 1 == v.size())
        throw std::invalid_argument("--map needs NAME=FILE, got \"" + v + "\"");
      out.maps.emplace_back(v.substr(0, eq), v.substr(eq + 1));
    } else if (a == "--queue-size") out.queue_size = parse_count(a, v, 0, 100'000);
    else if (a == "--device-queue-size") out.device_queue_size = parse_count(a, v, 1, 1'000'000);
    else if (a == "--cache-size") out.cache_size = parse_count(a, v, 0, 1'000'000);
    else if (a == "--http") out.http = v;
    else if (a == "--max-message-mib") out.limits.max_message_bytes = parse_count(a, v, 1, 1024) << 20;
    else if (a == "--keep-jobs") out.keep_jobs = parse_count(a, v, 0, 100'000'000);
    else if (a == "--keep-days") out.keep_days = parse_count(a, v, 0, 100'000);
    else if (!parse_limit_flag(a, v, out.limits)) throw std::invalid_argument("unknown option " + a + " (see --help)");
  }
  out.validate();
  return out;
}

void ServerOptions::validate() const {
  if (listen.empty()) throw std::invalid_argument("--listen HOST:PORT is required");
  if (listen.rfind(':') == std::string::npos) throw std::invalid_argument("--listen needs HOST:PORT, got \"" + listen + "\"");
  if (auth_file.empty() && !is_loopback_listen(listen))
    throw std::invalid_argument("--listen " + listen +
                                " is not a loopback address: without --auth the server lets every caller do "
                                "everything, so it listens only on 127.0.0.1, localhost or [::1]; give --auth FILE");
  if (!auth_file.empty() && !is_loopback_listen(listen) && tls_cert.empty() && !trusted_network)
    throw std::invalid_argument("--listen " + listen + " with --auth but without TLS would send the bearer tokens "
                                "in the clear; give --tls-cert and --tls-key, or --trusted-network if the network "
                                "is private");
  if (tls_cert.empty() != tls_key.empty()) throw std::invalid_argument("--tls-cert and --tls-key go together");
  if (!http.empty()) {
    if (http.rfind(':') == std::string::npos) throw std::invalid_argument("--http needs HOST:PORT, got \"" + http + "\"");
    if (auth_file.empty() && !is_loopback_listen(http))
      throw std::invalid_argument("--http " + http + " is not a loopback address: without --auth every caller may do "
                                  "everything; give --auth FILE");
    if (!tls_cert.empty())
      throw std::invalid_argument("--http with --tls-cert: the viewer's gateway speaks plaintext gRPC; start "
                                  "hapticjam-web by itself (docs/web.md)");
  }
  if (workers < 0) throw std::invalid_argument("--workers must be at least 1");
  if (db_file.empty()) throw std::invalid_argument("--db needs a file name");
}

int ServerOptions::worker_count() const {
  if (workers > 0) return workers;
  const unsigned cores = std::thread::hardware_concurrency();
  return cores > 0 ? int(cores) : 1;
}

}  // namespace hj::server
