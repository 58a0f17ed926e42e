#pragma once
// A gtest fixture for tests that run the piezoshift program (path in PIEZOSHIFT_CLI): a fresh
// temporary folder per test, files written into it, and run() giving the exit status, stdout and
// stderr of `piezoshift <args>` (args go through the shell: quote paths).
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

namespace piezoshift::testing {

struct CliResult {
  int status = -1;
  std::string out;
  std::string err;
};

class CliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::temp_directory_path() /
           ("piezoshift_cli_" + std::string(info->test_suite_name()) + "_" + info->name() + "_" +
            std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name) << text;
    return path(name);
  }

  //! The whole content of a file (empty if it cannot be read).
  static std::string read_text(const std::string& file) {
    std::ifstream in(file);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  }

  CliResult run(const std::string& args) const {
    const std::string err_path = path("stderr.txt");
    const std::string cmd =
        std::string("'") + PIEZOSHIFT_CLI + "' " + args + " 2>'" + err_path + "'";
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
    std::ifstream e(err_path);
    std::stringstream ss;
    ss << e.rdbuf();
    r.err = ss.str();
    return r;
  }

  std::filesystem::path dir_;
};

}  // namespace piezoshift::testing
