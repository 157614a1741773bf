// The server's command line: what `hapticjam-server --help` documents.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "server_limits.h"

namespace hj::server {

extern const char* const kServerUsage;

struct ServerOptions {
  std::string listen;                 // HOST:PORT; port 0 picks a free one
  std::string device;                 // HOST:PORT or a serial device; "" = none
  int workers = 0;                    // planning workers; 0 = one per core
  std::string auth_file;              // "" = no auth, loopback only
  std::string db_file = "hapticjam-queue.db";
  std::string tls_cert, tls_key;      // PEM files; both or neither
  bool trusted_network = false;       // --auth without TLS off loopback is allowed
  std::vector<std::pair<std::string, std::string>> maps;  // NAME, FILE
  int queue_size = 16;                // planning requests that may wait for a worker
  int device_queue_size = 64;         // device jobs that may wait
  int cache_size = 256;               // planning results kept
  std::string http;                   // HOST:PORT of the web viewer (clients/web, docs/web.md); "" = none
  int keep_jobs = 1000;               // finished device jobs kept (newest); 0 = no bound
  int keep_days = 30;                 // finished device jobs kept no longer; 0 = no bound
  ServerLimits limits;

  // Throws std::invalid_argument naming the flag: no --listen, a non-loopback
  // --listen or --http without --auth, or with --auth but neither TLS nor
  // --trusted-network, half of the TLS pair, --http with TLS, a count out of range.
  void validate() const;
  int worker_count() const;  // workers, or the core count
};

// Parses the arguments after the program name. Throws std::invalid_argument
// naming the flag. `help` is set for --help / -h (nothing else is checked).
ServerOptions parse_server_args(const std::vector<std::string>& args, bool* help);

// "127.0.0.1", "localhost", "::1", "[::1]" (the host part of HOST:PORT).
bool is_loopback_listen(const std::string& listen);

}  // namespace hj::server
