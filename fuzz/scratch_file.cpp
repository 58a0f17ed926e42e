#include "scratch_file.hpp"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>

#include <fmt/format.h>

namespace piezoshift::fuzz {
namespace {

// Removes the files at exit, so that fuzzing and the replay test leave nothing behind.
struct ScratchFiles {
  std::map<std::string, std::string, std::less<>> paths;  // name -> path
  ~ScratchFiles() {
    for (const auto& [name, path] : paths) {
      std::error_code ignored;
      std::filesystem::remove(path, ignored);
    }
  }
};

}  // namespace

std::string scratch_file(std::string_view name, std::string_view data) {
  static ScratchFiles files;
  auto it = files.paths.find(name);
  if (it == files.paths.end()) {
    const auto path = std::filesystem::temp_directory_path() /
                      fmt::format("piezoshift-fuzz-{}-{}", ::getpid(), name);
    it = files.paths.emplace(std::string(name), path.string()).first;
  }
  std::ofstream out(it->second, std::ios::binary | std::ios::trunc);
  out.write(data.data(), static_cast<std::streamsize>(data.size()));
  out.close();
  if (!out)  // the harness's own failure, not the input's
    throw std::runtime_error(fmt::format("fuzz: cannot write {}", it->second));
  return it->second;
}

}  // namespace piezoshift::fuzz
