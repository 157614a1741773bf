// hapticjam-server's start on a job database it cannot use: a clear message
// naming the file and exit code 3, at once (no crash, no retry loop).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <fstream>

#include "cli_runner.h"
#include "job_store.h"
#include "scratch_dir.h"

namespace hj {
namespace {

using namespace testing_support;

int run_server(const std::filesystem::path& db, const std::filesystem::path& dir) {
  const std::string command = quoted(HJ_SERVER_PATH) + " --listen 127.0.0.1:0 --db " + quoted(db) + " >" +
                              quoted(dir / "stdout.txt") + " 2>" + quoted(dir / "stderr.txt");
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(ServerStartup, ADatabaseThatIsNotOneExitsThreeNamingTheFile) {
  ScratchDir dir;
  const auto db = dir.path / "queue.db";
  std::ofstream(db) << std::string(8192, 'x');
  EXPECT_EQ(run_server(db, dir.path), 3);
  const std::string err = read_text(dir.path / "stderr.txt");
  EXPECT_NE(err.find("queue.db"), std::string::npos) << err;
  EXPECT_NE(err.find("not a database"), std::string::npos) << err;
}

TEST(ServerStartup, ASecondServerOnTheSameDatabaseRefusesToStart) {
  ScratchDir dir;
  const auto db = dir.path / "queue.db";
  server::JobStore first(db);  // the first server's hold on it
  EXPECT_EQ(run_server(db, dir.path), 3);
  const std::string err = read_text(dir.path / "stderr.txt");
  EXPECT_NE(err.find("in use by another server"), std::string::npos) << err;
}

}  // namespace
}  // namespace hj
