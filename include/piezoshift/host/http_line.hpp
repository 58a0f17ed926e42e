#pragma once
// Whether a line is HTTP's: a request line (`METHOD SP target SP HTTP/x.y`) or a header line
// (`Name: value`, Name a token of RFC 9110). A line-protocol port (GCS) closes a connection whose
// first line is either, before anything of it runs: a browser's `fetch` (even `no-cors`) or a
// `curl` to the GCS port would otherwise have its body executed, a line at a time. No GCS line
// looks like either: a command is 3 or 4 upper-case letters (or `*IDN`), an optional `?`, then
// arguments separated by spaces, never a token followed by `:`, nor a third word `HTTP/x.y`.
#include <string_view>

namespace piezoshift::host {

//! The line (without its LF and trailing CR) is an HTTP request line or header line.
bool looks_like_http(std::string_view line) noexcept;

}  // namespace piezoshift::host
