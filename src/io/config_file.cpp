#include "piezoshift/io/config_file.hpp"
#include "piezoshift/core/bounds.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>
#include <tuple>
#include <vector>

#include <fmt/core.h>
#include <toml++/toml.h>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/io/input_file.hpp"

namespace piezoshift::io {

struct ConfigFileImpl {
  std::string source;
  toml::table root;
  mutable std::set<std::string> used;      // dotted paths read so far
  mutable std::set<std::string> sections;  // sections asked for, with their parent tables

  [[noreturn]] void fail(const std::string& path, const toml::source_region& where,
                         const std::string& reason) const {
    if (where.begin.line > 0) {
      throw core::InputError(fmt::format("{}:{}:{}: {}: {}", source, where.begin.line,
                                         where.begin.column, path, reason));
    }
    throw core::InputError(fmt::format("{}: {}: {}", source, path, reason));
  }

  // The node of section.key, marked as read (so reject_unknown() passes it); nullptr when absent.
  // path receives the dotted name for messages.
  const toml::node* take(const std::string& section, std::string_view key,
                         std::string& path) const {
    const toml::node* n = find(section, key);
    if (n != nullptr) {
      path = section.empty() ? std::string(key) : section + "." + std::string(key);
      used.insert(path);
    }
    return n;
  }

  const toml::node* find(const std::string& section, std::string_view key) const {
    const toml::node* table = section.empty() ? &root : root.at_path(section).node();
    if (table == nullptr || !table->is_table())
      return nullptr;
    return table->as_table()->get(key);
  }

  double number(const std::string& path, const toml::node& n, core::Bounds b) const {
    double v = 0.0;
    if (const auto* f = n.as_floating_point()) {
      v = f->get();
    } else if (const auto* i = n.as_integer()) {
      v = static_cast<double>(i->get());
    } else {
      fail(path, n.source(),
           fmt::format("expected a number, found {}",
                       toml::impl::node_type_friendly_names[static_cast<int>(n.type())]));
    }
    if (!std::isfinite(v)) {
      fail(path, n.source(),
           fmt::format("value {} is not allowed: not a finite number (must be {})", v,
                       b.describe()));
    }
    if (!b.contains(v)) {
      fail(path, n.source(), fmt::format("value {} is not allowed: must be {}", v, b.describe()));
    }
    return v;
  }

  struct Unknown {
    std::string path;
    toml::source_region where;
    const char* reason;
  };

  // prefix."key" as the file spells it, for a key whose name holds a dot.
  static std::string quoted(const std::string& prefix, std::string_view key) {
    return fmt::format("{}{}\"{}\"", prefix, prefix.empty() ? "" : ".", key);
  }

  // A table nobody asked for is one unknown section (its keys are not listed one by one); inside
  // a section asked for, every key not read is unknown. Empty unknown tables count too.
  void collect_unknown(const toml::table& t, const std::string& prefix,
                       std::vector<Unknown>& out) const {
    for (const auto& [k, node] : t) {
      const std::string path =
          prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
      // A quoted key with a dot ("twin.daq.sample_time_s" = 1) is one key of that name, which no
      // read() asks for (they look keys up one table at a time), though its dotted path is that
      // of a real setting: refused by itself, not passed as the setting it spells.
      if (k.str().find('.') != std::string_view::npos) {
        out.push_back({quoted(prefix, k.str()), node.source(),
                       node.is_table() ? "unknown section: a quoted name with a dot is one name; "
                                         "write its parts unquoted ([a.b], not [\"a.b\"])"
                                       : "unknown key: a quoted name with a dot is one key; "
                                         "write its parts unquoted (a.b = 1, not \"a.b\" = 1)"});
        continue;
      }
      if (used.count(path))
        continue;
      if (node.is_table() && sections.count(path)) {
        collect_unknown(*node.as_table(), path, out);
      } else if (node.is_table()) {
        out.push_back({path, node.source(), "unknown section"});
      } else {
        out.push_back({path, node.source(), "unknown key (check its spelling and section)"});
      }
    }
  }
};

ConfigFile::ConfigFile(std::unique_ptr<ConfigFileImpl> impl) : impl_(std::move(impl)) {}
ConfigFile::ConfigFile(ConfigFile&&) noexcept = default;
ConfigFile& ConfigFile::operator=(ConfigFile&&) noexcept = default;
ConfigFile::~ConfigFile() = default;

ConfigFile ConfigFile::load(const std::string& path) {
  auto impl = std::make_unique<ConfigFileImpl>();
  impl->source = path;
  const std::string text = read_input_file(path, kMaxConfigFileBytes);
  try {
    impl->root = toml::parse(text, path);
  } catch (const toml::parse_error& e) {
    const auto& b = e.source().begin;
    throw core::InputError(
        fmt::format("{}:{}:{}: syntax error: {}", path, b.line, b.column, e.description()));
  }
  return ConfigFile(std::move(impl));
}

ConfigFile ConfigFile::parse(std::string_view text, const std::string& source_name) {
  auto impl = std::make_unique<ConfigFileImpl>();
  impl->source = source_name;
  try {
    impl->root = toml::parse(text, source_name);
  } catch (const toml::parse_error& e) {
    const auto& b = e.source().begin;
    throw core::InputError(
        fmt::format("{}:{}:{}: syntax error: {}", source_name, b.line, b.column, e.description()));
  }
  return ConfigFile(std::move(impl));
}

const std::string& ConfigFile::source() const {
  return impl_->source;
}

ConfigSection ConfigFile::section(std::string_view dotted_name) const {
  const std::string name(dotted_name);
  if (const toml::node* n = impl_->root.at_path(name).node(); n != nullptr && !n->is_table()) {
    impl_->fail(name, n->source(), "expected a section (table)");
  }
  // Asking for "a.b.c" makes "a", "a.b" and "a.b.c" known sections for reject_unknown().
  for (std::size_t dot = name.find('.'); dot != std::string::npos; dot = name.find('.', dot + 1))
    impl_->sections.insert(name.substr(0, dot));
  impl_->sections.insert(name);
  return ConfigSection(impl_.get(), name);
}

void ConfigFile::reject_unknown() const {
  std::vector<ConfigFileImpl::Unknown> unknown;
  impl_->collect_unknown(impl_->root, "", unknown);
  if (unknown.empty())
    return;
  // toml++ tables iterate in key order, not file order: report the one that comes first in the
  // file, so that fixing errors from the top down works.
  const auto first =
      std::min_element(unknown.begin(), unknown.end(),
                       [](const ConfigFileImpl::Unknown& a, const ConfigFileImpl::Unknown& b) {
                         return std::tuple(a.where.begin.line, a.where.begin.column, a.path) <
                                std::tuple(b.where.begin.line, b.where.begin.column, b.path);
                       });
  impl_->fail(first->path, first->where, first->reason);
}

bool ConfigSection::has(std::string_view key) const {
  return file_->find(name_, key) != nullptr;
}

std::string ConfigSection::location(std::string_view key) const {
  const toml::node* n = file_->find(name_, key);
  if (n == nullptr || n->source().begin.line == 0)
    return file_->source;
  return fmt::format("{}:{}:{}", file_->source, n->source().begin.line, n->source().begin.column);
}

bool ConfigSection::read(std::string_view key, double& value, core::Bounds bounds) const {
  const auto& impl = *file_;
  std::string path;
  const toml::node* n = impl.take(name_, key, path);
  if (n == nullptr)
    return false;
  value = impl.number(path, *n, bounds);
  return true;
}

bool ConfigSection::read(std::string_view key, std::int64_t& value, core::Bounds bounds) const {
  const auto& impl = *file_;
  std::string path;
  const toml::node* n = impl.take(name_, key, path);
  if (n == nullptr)
    return false;
  const auto* i = n->as_integer();
  if (i == nullptr)
    impl.fail(path, n->source(), "expected an integer");
  if (!bounds.contains(static_cast<double>(i->get()))) {
    impl.fail(path, n->source(),
              fmt::format("value {} is not allowed: must be {}", i->get(), bounds.describe()));
  }
  value = i->get();
  return true;
}

bool ConfigSection::read(std::string_view key, bool& value) const {
  const auto& impl = *file_;
  std::string path;
  const toml::node* n = impl.take(name_, key, path);
  if (n == nullptr)
    return false;
  const auto* b = n->as_boolean();
  if (b == nullptr)
    impl.fail(path, n->source(), "expected true or false");
  value = b->get();
  return true;
}

bool ConfigSection::read(std::string_view key, std::string& value) const {
  const auto& impl = *file_;
  std::string path;
  const toml::node* n = impl.take(name_, key, path);
  if (n == nullptr)
    return false;
  const auto* s = n->as_string();
  if (s == nullptr)
    impl.fail(path, n->source(), "expected a string");
  value = s->get();
  return true;
}

namespace {

// A list of exactly N numbers, each within bounds; path names the key for messages.
template <std::size_t N>
std::array<double, N> number_list(const ConfigFileImpl& impl, const std::string& path,
                                  const toml::node& n, core::Bounds bounds) {
  static constexpr const char* kCount[] = {"zero", "one", "two", "three", "four"};
  const auto* a = n.as_array();
  if (a == nullptr || a->size() != N) {
    impl.fail(path, n.source(), fmt::format("expected a list of {} numbers", kCount[N]));
  }
  std::array<double, N> v{};
  for (std::size_t i = 0; i < N; ++i) {
    v[i] = impl.number(fmt::format("{}[{}]", path, i), *a->get(i), bounds);
  }
  return v;
}

}  // namespace

bool ConfigSection::read(std::string_view key, std::array<double, 3>& value,
                         core::Bounds bounds) const {
  std::string path;
  const toml::node* n = file_->take(name_, key, path);
  if (n == nullptr)
    return false;
  value = number_list<3>(*file_, path, *n, bounds);
  return true;
}

bool ConfigSection::read(std::string_view key, std::array<double, 4>& value,
                         core::Bounds bounds) const {
  std::string path;
  const toml::node* n = file_->take(name_, key, path);
  if (n == nullptr)
    return false;
  value = number_list<4>(*file_, path, *n, bounds);
  return true;
}

bool ConfigSection::read(std::string_view key, std::vector<double>& value, std::size_t max_count,
                         core::Bounds bounds) const {
  const auto& impl = *file_;
  std::string path;
  const toml::node* n = impl.take(name_, key, path);
  if (n == nullptr)
    return false;
  const auto* a = n->as_array();
  if (a == nullptr || a->empty() || a->size() > max_count)
    impl.fail(path, n->source(), fmt::format("expected a list of 1 to {} numbers", max_count));
  value.clear();
  for (std::size_t i = 0; i < a->size(); ++i)
    value.push_back(impl.number(fmt::format("{}[{}]", path, i), *a->get(i), bounds));
  return true;
}

bool ConfigSection::read(std::string_view key, std::array<std::array<double, 3>, 3>& value,
                         core::Bounds bounds) const {
  const auto& impl = *file_;
  std::string path;
  const toml::node* n = impl.take(name_, key, path);
  if (n == nullptr)
    return false;
  const auto* rows = n->as_array();
  if (rows == nullptr || rows->size() != 3) {
    impl.fail(path, n->source(), "expected three rows of three numbers");
  }
  std::array<std::array<double, 3>, 3> m{};
  for (std::size_t r = 0; r < 3; ++r) {
    const auto* row = rows->get(r)->as_array();
    if (row == nullptr || row->size() != 3) {
      impl.fail(path, rows->get(r)->source(), fmt::format("row {} is not three numbers", r + 1));
    }
    for (std::size_t c = 0; c < 3; ++c) {
      m[r][c] = impl.number(fmt::format("{}[{}][{}]", path, r, c), *row->get(c), bounds);
    }
  }
  value = m;
  return true;
}

}  // namespace piezoshift::io
