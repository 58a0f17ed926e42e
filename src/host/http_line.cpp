#include "piezoshift/host/http_line.hpp"

#include <string_view>

namespace piezoshift::host {

namespace {

// RFC 9110's tchar.
bool token_char(char c) noexcept {
  if ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9'))
    return true;
  return std::string_view("!#$%&'*+-.^_`|~").find(c) != std::string_view::npos;
}

bool is_token(std::string_view s) noexcept {
  if (s.empty())
    return false;
  for (const char c : s)
    if (!token_char(c))
      return false;
  return true;
}

bool digit(char c) noexcept {
  return c >= '0' && c <= '9';
}

// HTTP/x.y (HTTP/2 and HTTP/3 as well: a client may write them).
bool http_version(std::string_view v) noexcept {
  if (!v.starts_with("HTTP/") || v.size() < 6)
    return false;
  v.remove_prefix(5);
  return v.size() == 1 ? digit(v[0]) : (v.size() == 3 && digit(v[0]) && v[1] == '.' && digit(v[2]));
}

}  // namespace

bool looks_like_http(std::string_view line) noexcept {
  const std::size_t colon = line.find(':');
  if (colon != std::string_view::npos && is_token(line.substr(0, colon)))
    return true;  // a header line
  const std::size_t s1 = line.find(' ');
  const std::size_t s2 = line.rfind(' ');
  if (s1 == std::string_view::npos || s2 == s1)
    return false;
  const std::string_view target = line.substr(s1 + 1, s2 - s1 - 1);
  return is_token(line.substr(0, s1)) && !target.empty() &&
         target.find(' ') == std::string_view::npos && http_version(line.substr(s2 + 1));
}

}  // namespace piezoshift::host
