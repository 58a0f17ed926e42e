// `piezoshift serve` driven as EPICS's motorPIGCS2 driver drives an E-727 (its
// PIasynController, PIE727Controller, PIGCSPiezoController, PIGCSController and PIInterface, read
// in epics-motor/motorPIGCS2; no code taken). The replay keeps the driver's framing: a command and
// its LF go in two writes (PIInterface::sendOnly), a query's LF goes with asyn's writeRead, which
// first flushes the input; an answer is read a line at a time (input EOS "\n") while a line ends
// in a space. Every answer is parsed as the driver parses it: the number after the first '='
// with atof/atoi (getValue), `#5` with strtol(.., 16), `ERR?` with atoi. Checked: the driver
// picks its E-727 class from *IDN?, every query is answered within 1 s, nothing is left unread
// before a query (no set command answers), `ERR?` is 0 after a good `MOV` although each poll
// reads parameters, the move ends on target, a P-term write reads back, and STP gives 10.
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include <fmt/core.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../support/spawned_process.hpp"

namespace {

namespace fs = std::filesystem;
using piezoshift::testing::slurp;
using piezoshift::testing::spawn;
using piezoshift::testing::Spawned;
using piezoshift::testing::wait_exit;

// The ten servo parameters the driver reads for every axis in every poll (PI727_CL_PARAM_ADDR),
// sent in decimal as the driver's "SPA? %s %d" does.
constexpr unsigned kServoParameters[] = {0x07000300, 0x07000301, 0x07030600, 0x08000100,
                                         0x08000101, 0x07000200, 0x07000201, 0x08000300,
                                         0x08000301, 0x06000500};
constexpr const char* kAxes[] = {"Z", "U", "V"};

// A socket used as asyn's octet port is: writes, writeRead with the input flushed first, reads
// ended by "\n".
class AsynLikePort {
 public:
  explicit AsynLikePort(std::uint16_t port) {
    fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    connected_ = ::connect(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
    const int one = 1;
    ::setsockopt(fd_, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);  // two writes, two segments
  }
  ~AsynLikePort() { ::close(fd_); }
  AsynLikePort(const AsynLikePort&) = delete;
  AsynLikePort& operator=(const AsynLikePort&) = delete;

  bool connected() const { return connected_; }

  // PIInterface::sendOnly: the command, then its LF in a second write.
  void send_only(const std::string& command) {
    write_all(command);
    write_all("\n");
  }
  // PIInterface::sendAndReceive: the command, then writeRead of its LF; the answer's lines joined
  // with their LFs, trailing spaces kept as the driver's buffer holds them.
  std::string query(const std::string& command) {
    write_all(command);
    return write_read("\n");
  }
  // PIInterface::sendAndReceive(char): writeRead of the byte alone.
  std::string query_byte(char byte) { return write_read(std::string(1, byte)); }

  std::size_t flushed_bytes() const { return flushed_; }
  double slowest_answer_s() const { return slowest_s_; }
  int answers() const { return answers_; }

 private:
  void write_all(const std::string& bytes) {
    ASSERT_EQ(::send(fd_, bytes.data(), bytes.size(), MSG_NOSIGNAL),
              static_cast<ssize_t>(bytes.size()));
  }
  std::string write_read(const std::string& bytes) {
    char junk[4096];  // asyn's flush: whatever waits unread is dropped (counted here)
    for (ssize_t n; (n = ::recv(fd_, junk, sizeof junk, MSG_DONTWAIT)) > 0;)
      flushed_ += static_cast<std::size_t>(n);
    const auto t0 = std::chrono::steady_clock::now();
    write_all(bytes);
    std::string answer;
    std::string line;
    do {
      line = read_line(t0);
      answer += line;
    } while (!line.empty() && line.size() >= 2 && line[line.size() - 2] == ' ');
    const double took_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    slowest_s_ = std::max(slowest_s_, took_s);
    ++answers_;
    return answer;
  }
  // One line up to its LF; empty when none came within 1 s of t0 (the test's limit).
  std::string read_line(std::chrono::steady_clock::time_point t0) {
    std::string line;
    for (;;) {
      const auto left =
          std::chrono::milliseconds(1000) - std::chrono::duration_cast<std::chrono::milliseconds>(
                                                std::chrono::steady_clock::now() - t0);
      pollfd p{fd_, POLLIN, 0};
      if (left.count() <= 0 || ::poll(&p, 1, static_cast<int>(left.count())) != 1)
        return {};
      char c = 0;
      if (::recv(fd_, &c, 1, 0) != 1)
        return {};
      line += c;
      if (c == '\n')
        return line;
    }
  }

  int fd_ = -1;
  bool connected_ = false;
  std::size_t flushed_ = 0;
  double slowest_s_ = 0.0;
  int answers_ = 0;
};

// PIGCSController::getValue: the number after the first '=', strictly (the driver's atof would
// read garbage as 0; here the number must end its line).
bool value_after_equals(const std::string& answer, double& value) {
  const char* p = std::strstr(answer.c_str(), "=");
  if (p == nullptr)
    return false;
  char* end = nullptr;
  value = std::strtod(p + 1, &end);
  return end != p + 1 && (*end == '\0' || *end == ' ' || *end == '\n');
}

class EpicsDriverReplay : public piezoshift::testing::TempDirTest {
 protected:
  void TearDown() override {
    if (server_.pid > 0) {
      kill(server_.pid, SIGKILL);
      wait_exit(server_);
    }
    TempDirTest::TearDown();
  }

  std::uint16_t start() {
    const std::string calibration = path("twin.toml");
    const std::string cmd = "'" + piezoshift::testing::cli_path() +
                            "' calibrate --pid paper --out '" + calibration + "' >/dev/null";
    if (std::system(cmd.c_str()) != 0) {
      ADD_FAILURE() << cmd;
      return 0;
    }
    server_ = spawn({"serve", "--port", "0", "--max-overruns", "1000000", "--json", "--calibration",
                     calibration},
                    path("out.txt"), path("err.txt"));
    return piezoshift::testing::wait_for_gcs_port(path("out.txt"), path("err.txt"));
  }

  int stop() {
    kill(server_.pid, SIGTERM);
    const int status = wait_exit(server_);
    server_.pid = -1;
    return status;
  }

  // PIGCSController::getGCSError.
  static int gcs_error(AsynLikePort& port) { return std::atoi(port.query("ERR?").c_str()); }

  // One axis's start-up (PIasynAxis::Init with PIGCSPiezoController::initAxis).
  static void init_axis(AsynLikePort& port, const char* axis) {
    port.send_only(fmt::format("SVO {} 1", axis));
    EXPECT_EQ(gcs_error(port), 0) << axis;
    double v = 0.0;
    for (const char* query : {"VEL?", "POS?", "TMN?", "TMX?"})
      EXPECT_TRUE(value_after_equals(port.query(fmt::format("{} {}", query, axis)), v))
          << query << " " << axis;
  }

  struct Poll {
    int moving = -1;
    int servo = -1;
    double position = NAN;
    int on_target = -1;
    int overflow = -1;
    double parameters[std::size(kServoParameters)]{};
  };
  // One poll of one axis (PIasynAxis::poll): #5, SVO?, POS? twice, ONT?, OVF?, the ten SPA?.
  static Poll poll_axis(AsynLikePort& port, int axis_no) {
    Poll r;
    const char* axis = kAxes[axis_no];
    const long mask = std::strtol(port.query_byte(5).c_str(), nullptr, 16);
    r.moving = (mask & (1L << axis_no)) != 0 ? 1 : 0;
    double v = 0.0;
    EXPECT_TRUE(value_after_equals(port.query(fmt::format("SVO? {}", axis)), v)) << axis;
    r.servo = static_cast<int>(v);
    EXPECT_TRUE(value_after_equals(port.query(fmt::format("POS? {}", axis)), r.position));
    EXPECT_TRUE(value_after_equals(port.query(fmt::format("POS? {}", axis)), r.position));
    EXPECT_TRUE(value_after_equals(port.query(fmt::format("ONT? {}", axis)), v)) << axis;
    r.on_target = static_cast<int>(v);
    EXPECT_TRUE(value_after_equals(port.query(fmt::format("OVF? {}", axis)), v)) << axis;
    r.overflow = static_cast<int>(v);
    for (std::size_t i = 0; i < std::size(kServoParameters); ++i)
      EXPECT_TRUE(value_after_equals(
          port.query(fmt::format("SPA? {} {}", axis, kServoParameters[i])), r.parameters[i]))
          << axis << " " << kServoParameters[i];
    return r;
  }
  static std::vector<Poll> poll_all(AsynLikePort& port) {
    std::vector<Poll> r;
    for (int a = 0; a < 3; ++a)
      r.push_back(poll_axis(port, a));
    return r;
  }

  Spawned server_;
};

TEST_F(EpicsDriverReplay, StartUpPollingAMoveAParameterWriteAndAStop) {
  const std::uint16_t port_no = start();
  ASSERT_NE(port_no, 0);
  AsynLikePort port(port_no);
  ASSERT_TRUE(port.connected());

  // Start-up: *IDN? picks the controller class (PIGCSController::CreateGCSController), then
  // PIGCSController::init (VEL?, SAI?) and each axis's Init.
  std::string idn = port.query("*IDN?");
  std::transform(idn.begin(), idn.end(), idn.begin(), [](char c) { return std::toupper(c); });
  EXPECT_NE(idn.find("E-727"), std::string::npos) << idn;
  EXPECT_NE(idn.find("PIEZOSHIFT"), std::string::npos) << idn;
  double v = 0.0;
  EXPECT_TRUE(value_after_equals(port.query("VEL?"), v));
  std::string sai = port.query("SAI?");
  std::vector<std::string> axes;
  for (char* tok = std::strtok(sai.data(), "\n"); tok != nullptr;
       tok = std::strtok(nullptr, "\n")) {
    std::string a(tok);
    a.erase(a.find_last_not_of(' ') + 1);
    axes.push_back(a);
  }
  ASSERT_EQ(axes, (std::vector<std::string>{"Z", "U", "V"}));
  for (const char* axis : kAxes)
    init_axis(port, axis);

  // Polling at rest: the servo on, the E-727 parameters answered, no error left behind.
  std::vector<Poll> rest = poll_all(port);
  for (const Poll& p : rest) {
    EXPECT_EQ(p.servo, 1);
    EXPECT_EQ(p.overflow, 0);         // at rest: a PID at 0 V on target is no overflow
    EXPECT_GT(p.parameters[0], 0.0);  // the P term
    EXPECT_EQ(p.parameters[2], 1.0);  // feedforward
    EXPECT_EQ(p.parameters[3], 0.0);  // no notch filter
  }
  EXPECT_EQ(gcs_error(port), 0);

  // A move (PIGCSController::move): ERR? 0 right after it, then polled until done and on target.
  port.send_only("MOV Z 5.000000");
  EXPECT_EQ(gcs_error(port), 0);
  Poll z;
  for (int i = 0; i < 200; ++i) {
    z = poll_all(port)[0];
    if (z.moving == 0 && z.on_target == 1)
      break;
  }
  EXPECT_EQ(z.moving, 0);
  EXPECT_EQ(z.on_target, 1);
  EXPECT_NEAR(z.position, 5.0, 0.01);
  EXPECT_EQ(z.overflow, 0);  // mid-travel, every PID within its range

  // A parameter write (PIE727Controller::setCLAxisParam): CCL 1 advanced, SPA, CCL 0, no ERR?;
  // the next poll reads it back on every axis (one loop drives them all).
  const double kp = rest[0].parameters[0] * 0.9;
  port.send_only("CCL 1 advanced");
  port.send_only(fmt::format("SPA Z {} {:.12g}", kServoParameters[0], kp));
  port.send_only("CCL 0");
  for (const Poll& p : poll_all(port))
    EXPECT_NEAR(p.parameters[0], kp, 1e-12 * kp);
  EXPECT_EQ(gcs_error(port), 0);
  port.send_only("MOV Z 3.000000");
  EXPECT_EQ(gcs_error(port), 0);
  for (int i = 0; i < 200; ++i) {
    z = poll_all(port)[0];
    if (z.moving == 0 && z.on_target == 1)
      break;
  }
  EXPECT_EQ(z.on_target, 1);
  EXPECT_NEAR(z.position, 3.0, 0.01);

  // Stop (PIGCSPiezoController::haltAxis): STP, then ERR? must be 10.
  port.send_only("STP");
  EXPECT_EQ(gcs_error(port), 10);
  EXPECT_EQ(gcs_error(port), 0);

  std::printf("replay: %d answers, the slowest in %.1f ms\n", port.answers(),
              1e3 * port.slowest_answer_s());
  EXPECT_EQ(port.flushed_bytes(), 0u);  // no set command answered anything
  EXPECT_LT(port.slowest_answer_s(), 1.0) << port.answers() << " answers";
  EXPECT_GT(port.answers(), 100);
  EXPECT_EQ(stop(), 0) << slurp(path("err.txt"));
  const std::string out = slurp(path("out.txt"));
  const std::size_t brace = out.find('{');
  ASSERT_NE(brace, std::string::npos) << out;
  EXPECT_EQ(nlohmann::json::parse(out.substr(brace)).at("faults"), 0);
}

// After SVO at the bottom of the travel a PID rests at 0 V, its lower limit, and OVF?
// read 1 on every axis at every poll, so the driver flagged an idle, healthy stage. PI's OVF? is
// the control variables out of range while the loop cannot hold its target: 0 here.
TEST_F(EpicsDriverReplay, IdlePollingAtTheBottomOfTheTravelReadsNoOverflow) {
  const std::uint16_t port_no = start();
  ASSERT_NE(port_no, 0);
  AsynLikePort port(port_no);
  ASSERT_TRUE(port.connected());
  for (const char* axis : kAxes)
    init_axis(port, axis);
  int polls = 0;
  for (int round = 0; round < 20; ++round) {
    for (const Poll& p : poll_all(port)) {
      EXPECT_EQ(p.servo, 1);
      EXPECT_EQ(p.overflow, 0) << "round " << round;
      ++polls;
    }
  }
  const Poll z = poll_axis(port, 0);
  EXPECT_LT(std::fabs(z.position), 0.5);  // at the bottom of the travel
  EXPECT_EQ(z.on_target, 1);
  EXPECT_EQ(polls, 60);
  EXPECT_EQ(gcs_error(port), 0);
  EXPECT_EQ(stop(), 0) << slurp(path("err.txt"));
}

}  // namespace
