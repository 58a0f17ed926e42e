#include "piezoshift/host/http_request.hpp"

#include <cctype>
#include <charconv>
#include <vector>

namespace piezoshift::host {

namespace {

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t'))
    s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t'))
    s.remove_suffix(1);
  return s;
}

// %XX and '+' decoding of a query component; false on a malformed escape.
bool url_decode(std::string_view in, std::string& out) {
  out.clear();
  for (std::size_t i = 0; i < in.size(); ++i) {
    if (in[i] == '+') {
      out += ' ';
    } else if (in[i] == '%') {
      unsigned value = 0;
      if (i + 2 >= in.size())
        return false;
      const auto r = std::from_chars(in.data() + i + 1, in.data() + i + 3, value, 16);
      if (r.ec != std::errc() || r.ptr != in.data() + i + 3)
        return false;
      out += static_cast<char>(value);
      i += 2;
    } else {
      out += in[i];
    }
  }
  return true;
}

}  // namespace

HttpParse parse_http_request(std::string_view input, std::size_t max_head_bytes,
                             std::size_t max_body_bytes, HttpRequest& r) {
  std::size_t end = input.find("\r\n\r\n");
  std::size_t sep = 4;
  if (const std::size_t lf = input.find("\n\n"); lf != std::string_view::npos && lf < end) {
    end = lf;
    sep = 2;
  }
  if (end == std::string_view::npos)
    return input.size() > max_head_bytes ? HttpParse::kHeadersTooLarge : HttpParse::kIncomplete;
  if (end > max_head_bytes)
    return HttpParse::kHeadersTooLarge;

  std::string_view head(input.data(), end);
  std::vector<std::string_view> lines;
  while (!head.empty()) {
    const std::size_t lf = head.find('\n');
    std::string_view line = head.substr(0, lf);
    if (!line.empty() && line.back() == '\r')
      line.remove_suffix(1);
    lines.push_back(line);
    if (lf == std::string_view::npos)
      break;
    head.remove_prefix(lf + 1);
  }
  if (lines.empty())
    return HttpParse::kBad;
  // Request line: METHOD SP target SP HTTP/1.x
  const std::string_view rl = lines[0];
  const std::size_t s1 = rl.find(' ');
  const std::size_t s2 = rl.rfind(' ');
  if (s1 == std::string_view::npos || s2 == s1)
    return HttpParse::kBad;
  r.method = std::string(rl.substr(0, s1));
  const std::string_view target = rl.substr(s1 + 1, s2 - s1 - 1);
  const std::string_view version = rl.substr(s2 + 1);
  if (version != "HTTP/1.1" && version != "HTTP/1.0")
    return HttpParse::kBad;
  if (target.empty() || target.front() != '/')
    return HttpParse::kBad;
  const std::size_t q = target.find('?');
  r.path = std::string(target.substr(0, q));
  if (q != std::string_view::npos) {
    std::string_view query = target.substr(q + 1);
    while (!query.empty()) {
      const std::size_t amp = query.find('&');
      const std::string_view pair = query.substr(0, amp);
      const std::size_t eq = pair.find('=');
      std::string key, value;
      if (!url_decode(pair.substr(0, eq), key) ||
          !url_decode(eq == std::string_view::npos ? std::string_view{} : pair.substr(eq + 1),
                      value))
        return HttpParse::kBad;
      r.query[key] = value;
      if (amp == std::string_view::npos)
        break;
      query.remove_prefix(amp + 1);
    }
  }
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const std::size_t colon = lines[i].find(':');
    if (colon == std::string_view::npos || colon == 0)
      return HttpParse::kBad;
    const auto [it, added] = r.headers.insert_or_assign(
        lower(trim(lines[i].substr(0, colon))), std::string(trim(lines[i].substr(colon + 1))));
    // Two lengths (or hosts) are read differently by different parsers (request smuggling): one
    // or the request is refused, never the last taken.
    if (!added && (it->first == "content-length" || it->first == "host"))
      return HttpParse::kBad;
  }
  if (r.headers.count("transfer-encoding") != 0)
    return HttpParse::kBad;  // no chunked uploads: nothing here needs them
  std::size_t length = 0;
  if (const auto it = r.headers.find("content-length"); it != r.headers.end()) {
    const std::string& v = it->second;
    const auto res = std::from_chars(v.data(), v.data() + v.size(), length);
    if (res.ec != std::errc() || res.ptr != v.data() + v.size())
      return HttpParse::kBad;
    if (length > max_body_bytes)
      return HttpParse::kBodyTooLarge;
  }
  const std::size_t body_at = end + sep;
  if (input.size() < body_at + length)
    return HttpParse::kIncomplete;
  r.body = std::string(input.substr(body_at, length));
  return HttpParse::kDone;
}

std::string HttpRequest::header(const std::string& lower_name) const {
  const auto it = headers.find(lower_name);
  return it == headers.end() ? std::string{} : it->second;
}

}  // namespace piezoshift::host
