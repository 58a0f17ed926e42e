#pragma once
// A gtest fixture with a fresh temporary folder per test (removed afterwards), files written into
// it, and files read back whole. The folder's name holds the suite, the test and the process id,
// so that tests running in parallel never share one.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

namespace piezoshift::testing {

//! The whole content of a file (empty if it cannot be read).
inline std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class TempDirTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::temp_directory_path() /
           ("piezoshift_" + std::string(info->test_suite_name()) + "_" + info->name() + "_" +
            std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  //! Writes text to name in the folder; returns its path.
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name) << text;
    return path(name);
  }
  static std::string read_text(const std::string& file) { return slurp(file); }

  std::filesystem::path dir_;
};

}  // namespace piezoshift::testing
