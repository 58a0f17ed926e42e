#pragma once
// One HTTP/1.1 request as the dashboard's server (http_server.hpp) takes it, and its parser:
// "METHOD target HTTP/1.x" (LF or CRLF line ends), headers, a body only with Content-Length
// (no chunked uploads: nothing here needs them; any Transfer-Encoding is refused). A second
// Content-Length or Host header is refused (kBad), never the last one taken.
#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <string_view>

namespace piezoshift::host {

struct HttpRequest {
  std::string method;                          //!< "GET", "POST"
  std::string path;                            //!< "/api/stream", without the query
  std::map<std::string, std::string> query;    //!< decoded ?key=value pairs
  std::map<std::string, std::string> headers;  //!< names in lower case
  std::string body;
  //! The connection (its poll server's ClientId), set by the server: HttpResponse::later().
  std::uint64_t client = 0;
  std::string header(const std::string& lower_name) const;
};

enum class HttpParse { kIncomplete, kDone, kBad, kHeadersTooLarge, kBodyTooLarge };

//! Parses what a connection has sent so far. kIncomplete until the head and the body are whole;
//! kHeadersTooLarge once the request line and headers exceed max_head_bytes, also before they
//! end; kBodyTooLarge for a Content-Length beyond max_body_bytes; kBad for anything malformed.
HttpParse parse_http_request(std::string_view input, std::size_t max_head_bytes,
                             std::size_t max_body_bytes, HttpRequest& request);

}  // namespace piezoshift::host
