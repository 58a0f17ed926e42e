#pragma once
// Tests that need the piezoshift program alive while they act on it (signals, a server): start
// it with posix_spawn, stdout and stderr going to files, and wait for its exit status.
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "temp_dir_test.hpp"
#include "test_paths.hpp"

extern char** environ;

namespace piezoshift::testing {

struct Spawned {
  pid_t pid = -1;
};

//! Starts `piezoshift <args>` (cli_path()) with stdout and stderr to the given files.
inline Spawned spawn(const std::vector<std::string>& args, const std::string& out,
                     const std::string& err) {
  std::vector<char*> argv;
  std::string prog = cli_path();
  argv.push_back(prog.data());
  std::vector<std::string> copy = args;
  for (auto& a : copy)
    argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&fa, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  Spawned s;
  const int rc = posix_spawn(&s.pid, prog.c_str(), &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  EXPECT_EQ(rc, 0);
  return s;
}

//! Waits for the process; its exit status, or -1 when a signal ended it (reported through the
//! optional outputs).
inline int wait_exit(const Spawned& s, bool* signaled = nullptr, int* signo = nullptr) {
  int status = 0;
  waitpid(s.pid, &status, 0);
  if (signaled)
    *signaled = WIFSIGNALED(status);
  if (signo && WIFSIGNALED(status))
    *signo = WTERMSIG(status);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

//! The GCS port `serve` prints on its stdout (file out) once it listens ("GCS 2.0 on
//! 127.0.0.1:PORT,"), waiting up to 30 s; 0 with a test failure naming its stderr (file err) when
//! it does not come.
inline std::uint16_t wait_for_gcs_port(const std::string& out, const std::string& err) {
  const std::string marker = "GCS 2.0 on 127.0.0.1:";
  for (int i = 0; i < 3000; ++i) {
    const std::string text = slurp(out);
    const std::size_t at = text.find(marker);
    if (at != std::string::npos && text.find(',', at) != std::string::npos)
      return static_cast<std::uint16_t>(std::stoi(text.substr(at + marker.size())));
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ADD_FAILURE() << "server did not start: " << slurp(err);
  return 0;
}

}  // namespace piezoshift::testing
