#pragma once
// A gtest fixture for tests that run the piezoshift program (cli_path()): a fresh
// temporary folder per test (TempDirTest), and run() giving the exit status, stdout and stderr of
// `piezoshift <args>` (args go through the shell: quote paths).
#include <sys/wait.h>

#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "temp_dir_test.hpp"
#include "test_paths.hpp"

namespace piezoshift::testing {

struct CliResult {
  int status = -1;
  std::string out;
  std::string err;
};

class CliTest : public TempDirTest {
 protected:
  CliResult run(const std::string& args) const {
    const std::string err_path = path("stderr.txt");
    const std::string cmd = "'" + cli_path() + "' " + args + " 2>'" + err_path + "'";
    CliResult r;
    FILE* pipe = ::popen(cmd.c_str(), "r");
    if (pipe == nullptr) {
      ADD_FAILURE() << "popen failed: " << cmd;
      return r;
    }
    char buf[4096];
    for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, pipe)) > 0;)
      r.out.append(buf, n);
    const int w = ::pclose(pipe);
    r.status = WIFEXITED(w) ? WEXITSTATUS(w) : -1;
    r.err = slurp(err_path);
    return r;
  }
};

}  // namespace piezoshift::testing
