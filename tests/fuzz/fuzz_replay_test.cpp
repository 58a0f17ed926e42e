// Every seed of fuzz/corpus/<target> and every reproducer of fuzz/regressions/<target> through
// the same entry point the libFuzzer binary calls (fuzz/entry_points.hpp): an input that once
// crashed, hung or escaped as an internal error stays fixed, in the normal suite and under
// ASan + UBSan. (A hang is left to ctest's timeout; `make fuzz` holds each input to 1 s.)
#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <ostream>
#include <string>
#include <vector>

#include "../support/test_paths.hpp"
#include "entry_points.hpp"

namespace piezoshift::fuzz {
namespace {

namespace fs = std::filesystem;

std::vector<fs::path> inputs(const std::string& kind, const std::string& target) {
  const fs::path dir = fs::path(testing::source_dir()) / "fuzz" / kind / target;
  std::vector<fs::path> files;
  if (fs::is_directory(dir))
    for (const fs::directory_entry& e : fs::directory_iterator(dir))
      if (e.is_regular_file())
        files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

std::string read(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

// Test names and messages show the target's name.
void PrintTo(const Target& target, std::ostream* os) {
  *os << target.name;
}

namespace {

// The subcommands' reports (JSON on stdout) go nowhere while it lives, as with libFuzzer's
// -close_fd_mask=1 in `make fuzz`.
class QuietStdout {
 public:
  QuietStdout() : saved_(::dup(STDOUT_FILENO)) {
    std::fflush(stdout);
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, STDOUT_FILENO);
    ::close(null);
  }
  ~QuietStdout() {
    std::fflush(stdout);
    ::dup2(saved_, STDOUT_FILENO);
    ::close(saved_);
  }
  QuietStdout(const QuietStdout&) = delete;
  QuietStdout& operator=(const QuietStdout&) = delete;

 private:
  int saved_;
};

class FuzzReplay : public ::testing::TestWithParam<Target> {};

TEST_P(FuzzReplay, EveryCorpusSeedAndRegressionIsHandledAsInput) {
  const Target target = GetParam();
  std::vector<fs::path> files = inputs("corpus", target.name);
  // A target without seeds would start from nothing and CI's 60 s would find little.
  EXPECT_GE(files.size(), 3u) << "fuzz/corpus/" << target.name;
  const std::vector<fs::path> regressions = inputs("regressions", target.name);
  files.insert(files.end(), regressions.begin(), regressions.end());
  for (const fs::path& file : files) {
    SCOPED_TRACE(file.string());
    const std::string data = read(file);
    try {
      const QuietStdout quiet;
      target.entry(data);
    } catch (const std::exception& e) {
      ADD_FAILURE() << "escaped as an internal error: " << e.what();
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Targets, FuzzReplay,
                         ::testing::ValuesIn(targets().begin(), targets().end()),
                         [](const ::testing::TestParamInfo<Target>& param) {
                           return std::string(param.param.name);
                         });

}  // namespace
}  // namespace piezoshift::fuzz
