#pragma once
// Reading TOML configuration files (toml++) into the project's parameter structs.
//
//   io::ConfigFile cfg = io::ConfigFile::load("my.toml");
//   io::ConfigSection a = cfg.section("actuator");
//   a.read("stiffness_N_per_um", params.stiffness_N_per_um, core::Bounds::positive());
//   cfg.reject_unknown();   // every key in the file must have been read by someone
//
// A key that is absent leaves the struct's default (the paper's value) untouched. A wrong type, a
// value out of bounds, NaN or infinity, a syntax error, and (through reject_unknown) a key or
// section nobody asked for each throw core::InputError naming the file, the key and the reason.
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "piezoshift/core/bounds.hpp"

namespace piezoshift::io {

class ConfigFile;
struct ConfigFileImpl;  // the parsed document; lives on the heap, so sections survive a move

//! One [section] (or [a.b] nested table) of a configuration file. Absent sections read as empty.
class ConfigSection {
 public:
  //! Each read() leaves value untouched when the key is absent; returns whether it was present.
  bool read(std::string_view key, double& value, core::Bounds bounds = core::Bounds::any()) const;
  bool read(std::string_view key, std::int64_t& value,
            core::Bounds bounds = core::Bounds::any()) const;
  bool read(std::string_view key, bool& value) const;
  bool read(std::string_view key, std::string& value) const;
  bool read(std::string_view key, std::array<double, 3>& value,
            core::Bounds bounds = core::Bounds::any()) const;
  //! A list of four numbers (e.g. the cubic's p = [p3, p2, p1, p0]).
  bool read(std::string_view key, std::array<double, 4>& value,
            core::Bounds bounds = core::Bounds::any()) const;
  //! A list of 1 to max_count numbers.
  bool read(std::string_view key, std::vector<double>& value, std::size_t max_count,
            core::Bounds bounds = core::Bounds::any()) const;
  //! A 3x3 matrix as a list of three rows.
  bool read(std::string_view key, std::array<std::array<double, 3>, 3>& value,
            core::Bounds bounds = core::Bounds::any()) const;

  bool has(std::string_view key) const;
  //! "FILE:LINE:COLUMN" of the key's value, for a message about a value checked after reading
  //! (with others); the file's name alone when the key is absent.
  std::string location(std::string_view key) const;
  const std::string& name() const { return name_; }

 private:
  friend class ConfigFile;
  ConfigSection(const ConfigFileImpl* file, std::string name)
      : file_(file), name_(std::move(name)) {}
  const ConfigFileImpl* file_;  // valid while the ConfigFile (moved or not) lives
  std::string name_;
};

class ConfigFile {
 public:
  //! Parses a file; a missing file or a syntax error throws InputError with file, line, column.
  static ConfigFile load(const std::string& path);
  //! Parses text (tests, built-in defaults); source_name stands in for the file name in messages.
  static ConfigFile parse(std::string_view text, const std::string& source_name);

  ConfigFile(ConfigFile&&) noexcept;
  ConfigFile& operator=(ConfigFile&&) noexcept;
  ~ConfigFile();

  //! A dotted name reaches nested tables: section("twin.amplifier").
  ConfigSection section(std::string_view dotted_name) const;
  //! Throws InputError naming the first key (in file order) that no read() asked for.
  void reject_unknown() const;

  const std::string& source() const;

 private:
  explicit ConfigFile(std::unique_ptr<ConfigFileImpl> impl);
  std::unique_ptr<ConfigFileImpl> impl_;
};

}  // namespace piezoshift::io
