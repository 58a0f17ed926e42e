#pragma once
// A blocking PI GCS 2.0 client over TCP, with timeouts: used by the tests of `piezoshift serve`
// and by `piezoshift gcs`.
//
// GCS 2.0 framing: a command is one ASCII line ending in LF. An answer may span several lines;
// every line but the last ends with a SPACE before its LF, so an answer ends at the first LF that
// does not follow a space:
//   "0 1 X=1.0 \n0 1 Y=2.0 \n0 1 Z=3.0\n"  is one answer of three lines.
// An answer is bounded: beyond max_answer_bytes (by default the largest piezoshift's server
// makes, DataRecorder::kMaxAnswerBytes, a DRR? of 8 tables x 8192 points) read_answer() throws
// instead of buffering a server that never ends its answer (8.6 GB in 40 s before the bound).
// Not real-time code; errors are std::runtime_error naming host:port.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "piezoshift/host/data_recorder.hpp"

namespace piezoshift::host {

class GcsClient {
 public:
  //! Connects within timeout_s [s] (+inf: no limit); throws std::runtime_error naming host:port
  //! (unknown host, refused, timed out). host: a name or a numeric address. max_answer_bytes:
  //! the longest answer read_answer() takes.
  GcsClient(const std::string& host, std::uint16_t port, double timeout_s = 5.0,
            std::size_t max_answer_bytes = DataRecorder::kMaxAnswerBytes);
  ~GcsClient();
  GcsClient(const GcsClient&) = delete;
  GcsClient& operator=(const GcsClient&) = delete;

  //! Sends command followed by LF.
  void send(std::string_view command);
  //! Sends bytes exactly as given (tests: garbage, no LF, huge lines). Throws when the socket
  //! takes nothing for timeout_s or the peer is gone.
  void send_raw(std::string_view bytes);
  //! Reads one whole answer, exactly as received (terminators included). Throws
  //! std::runtime_error when no byte arrives for timeout_s, on EOF or reset before its end, or
  //! once more than max_answer_bytes of it have arrived without its end.
  std::string read_answer();
  //! read_answer() split into its lines, without their " \n" or "\n".
  std::vector<std::string> read_answer_lines();
  //! send() then read_answer().
  std::string query(std::string_view command);
  //! send() then read_answer_lines().
  std::vector<std::string> query_lines(std::string_view command);
  //! Reads and discards until the peer closes (EOF or reset): true if it does within timeout_s.
  bool wait_closed(double timeout_s);
  //! Closes the connection (idempotent); a closed client throws on send and read.
  void close() noexcept;

  //! Splits one answer as returned by read_answer() into its lines.
  static std::vector<std::string> split_answer(std::string_view answer);

 private:
  //! Waits for events on the socket up to timeout_s; false on timeout.
  bool wait_for(short events, double timeout_s);
  //! Appends what arrives to buffer_; false on EOF. Throws on timeout or error.
  bool receive_some();
  void require_open() const;

  std::string where_;  // "host:port", for messages
  double timeout_s_;
  std::size_t max_answer_bytes_;
  int fd_ = -1;
  std::string buffer_;       // received, not yet returned
  std::size_t scanned_ = 0;  // buffer_[0, scanned_) holds no answer terminator
};

}  // namespace piezoshift::host
