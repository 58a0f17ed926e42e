// aravis:ID over GigE Vision: Aravis's arv-fake-gv-camera-0.8 (Debian's aravis-tools) started by
// the test as a child on 127.0.0.1 and opened through Aravis's discovery, like a camera on the
// network. Integration tier: a child process and loopback sockets (docs/testing.md).
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <string>
#include <thread>
#include <vector>

#include "piezoshift/camera/aravis_camera.hpp"

extern char** environ;

namespace piezoshift::camera {
namespace {

#ifdef PIEZOSHIFT_ARV_FAKE_GV_CAMERA
//! The child, killed and reaped whatever the test's outcome. One at a time on this machine:
//! two fake GV cameras both bind 127.0.0.1's GVCP port 3956 and then answer each other's
//! controller (a PixelFormat write timed out when ctest -j2 ran two), so the child runs under an
//! exclusive lock on a file in /tmp, shared by every test run and worktree here.
class FakeGvCamera {
 public:
  //! lost_per_thousand: the packets it drops on purpose (its -r), 0 for none.
  explicit FakeGvCamera(const std::string& serial, int lost_per_thousand = 0) {
    lock_fd_ = open("/tmp/piezoshift-arv-fake-gv-camera.lock", O_CREAT | O_RDWR | O_CLOEXEC, 0666);
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (lock_fd_ >= 0 && flock(lock_fd_, LOCK_EX | LOCK_NB) != 0) {
      if (std::chrono::steady_clock::now() > give_up)
        return;  // running() is false: the test says so
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    std::vector<std::string> args = {
        PIEZOSHIFT_ARV_FAKE_GV_CAMERA,    "-i", "127.0.0.1", "-s", serial, "-r",
        std::to_string(lost_per_thousand)};
    std::vector<char*> argv;
    for (auto& a : args)
      argv.push_back(a.data());
    argv.push_back(nullptr);
    if (posix_spawn(&pid_, argv[0], nullptr, nullptr, argv.data(), environ) != 0) {
      pid_ = -1;
      return;
    }
    // It exits at once ("Failed to start camera") when it cannot listen on 127.0.0.1.
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    if (waitpid(pid_, nullptr, WNOHANG) != 0)
      pid_ = -1;
  }
  FakeGvCamera(const FakeGvCamera&) = delete;
  FakeGvCamera& operator=(const FakeGvCamera&) = delete;
  ~FakeGvCamera() {
    stop_child();
    if (lock_fd_ >= 0)
      close(lock_fd_);  // releases the lock, after the child is gone
  }
  bool running() const { return pid_ > 0; }

 private:
  void stop_child() {
    if (pid_ <= 0)
      return;
    kill(pid_, SIGTERM);
    for (int i = 0; i < 50; ++i) {
      if (waitpid(pid_, nullptr, WNOHANG) == pid_)
        return;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
  }
  pid_t pid_ = -1;
  int lock_fd_ = -1;
};
#endif

CameraSettings gv_settings() {
  CameraSettings s;
  s.width_px = 256;
  s.height_px = 256;
  s.format = PixelFormat::kMono16;
  s.exposure_s = 10e-3;  // the fake's ramp is unscaled at 10 ms and gain 0
  s.gain_dB = 0.0;
  s.trigger = TriggerSource::kSoftware;
  s.buffer_count = 8;
  return s;
}

TEST(AravisFakeGvCamera, HundredFramesOverLoopbackNoneLost) {
  if (!aravis_available())
    GTEST_SKIP() << "built without Aravis (libaravis-dev): aravis: cannot be tested";
#ifndef PIEZOSHIFT_ARV_FAKE_GV_CAMERA
  GTEST_SKIP() << "arv-fake-gv-camera-0.8 (aravis-tools) was not found at build time";
#else
  const std::string serial = "PZ" + std::to_string(getpid());
  FakeGvCamera child(serial);
  ASSERT_TRUE(child.running())
      << "arv-fake-gv-camera-0.8 did not stay up on 127.0.0.1 (or its lock was held for 60 s)";
  auto camera = make_aravis_camera("Aravis-Fake-" + serial);
  camera->configure(gv_settings());
  camera->start();
  Frame frame;
  std::uint64_t first_id = 0;
  std::int64_t last_device_ns = 0;
  for (int i = 0; i < 100; ++i) {
    // The fake GV camera looks at its TriggerSoftware register 25 times a second and latches
    // one trigger: one trigger per frame, the next once the frame is in.
    ASSERT_TRUE(camera->trigger(0.01 * i)) << camera->message();
    ASSERT_EQ(camera->wait(frame, 2.0), FrameStatus::kOk) << i << ": " << camera->message();
    if (i == 0)
      first_id = frame.frame_id;
    ASSERT_EQ(frame.frame_id, first_id + i);
    ASSERT_EQ(frame.trigger_time_s, 0.01 * i);
    ASSERT_GT(frame.device_timestamp_ns, last_device_ns);  // the leader's, one per frame
    last_device_ns = frame.device_timestamp_ns;
    ASSERT_EQ(frame.width_px, 256);
    ASSERT_EQ(frame.height_px, 256);
    ASSERT_EQ(frame.format, PixelFormat::kMono16);
    ASSERT_EQ(frame.counts.size(), 256u * 256u);
    // The fake's diagonal ramp at (x, y) = (232, 3) for its 16-bit frame id (1 after 65535).
    const std::uint64_t device_id = (frame.frame_id - 1) % 65535 + 1;
    ASSERT_EQ(frame.counts[3 * 256 + 232], (256 * 232 + 256 * device_id + 256 * 3) % 65535);
  }
  EXPECT_EQ(camera->lost_frames(), 0u);
  camera->stop();
#endif
}

TEST(AravisFakeGvCamera, DroppedPacketsAreLostFramesWithTheirIdsNeverSkipped) {
  if (!aravis_available())
    GTEST_SKIP() << "built without Aravis (libaravis-dev): aravis: cannot be tested";
#ifndef PIEZOSHIFT_ARV_FAKE_GV_CAMERA
  GTEST_SKIP() << "arv-fake-gv-camera-0.8 (aravis-tools) was not found at build time";
#else
  // 2 % of its packets dropped and never resent (the fake ignores resend requests): about one
  // frame in three misses a packet (19 packets of 8 KiB a frame).
  const std::string serial = "PL" + std::to_string(getpid());
  FakeGvCamera child(serial, 20);
  ASSERT_TRUE(child.running())
      << "arv-fake-gv-camera-0.8 did not stay up on 127.0.0.1 (or its lock was held for 60 s)";
  auto camera = make_aravis_camera("Aravis-Fake-" + serial);
  camera->configure(gv_settings());
  camera->start();
  std::vector<FrameStatus> statuses;
  std::vector<std::uint64_t> ids;
  Frame frame;
  for (int i = 0; i < 30; ++i) {
    ASSERT_TRUE(camera->trigger(i)) << camera->message();
    // A frame whose every packet was dropped shows up as a gap at the next one: then nothing
    // arrives for this trigger, and two events for the next.
    for (FrameStatus st = camera->wait(frame, 1.0); st != FrameStatus::kTimeout;
         st = camera->poll(frame)) {
      if (st == FrameStatus::kNone)
        break;
      statuses.push_back(st);
      ids.push_back(frame.frame_id);
      if (st == FrameStatus::kLost) {
        EXPECT_TRUE(camera->message().find("frame lost") != std::string::npos) << camera->message();
      }
    }
  }
  camera->stop();
  for (FrameStatus st; (st = camera->poll(frame)) != FrameStatus::kNone;) {
    statuses.push_back(st);
    ids.push_back(frame.frame_id);
  }
  const auto lost = std::count(statuses.begin(), statuses.end(), FrameStatus::kLost);
  const auto ok = std::count(statuses.begin(), statuses.end(), FrameStatus::kOk);
  EXPECT_GT(lost, 0);  // P(no loss in 30 frames) ~ 1e-5
  EXPECT_GT(ok, 0);
  EXPECT_EQ(ok + lost, static_cast<long>(statuses.size()));  // no kError
  EXPECT_EQ(camera->lost_frames(), static_cast<std::uint64_t>(lost));
  // One event per frame id, in order: a loss is reported, never skipped. A first frame lost
  // with its leader has no id (0).
  const std::size_t first = !ids.empty() && ids[0] == 0 && statuses[0] == FrameStatus::kLost;
  for (std::size_t i = first + 1; i < ids.size(); ++i)
    EXPECT_EQ(ids[i], ids[first] + (i - first)) << "event " << i;
#endif
}

}  // namespace
}  // namespace piezoshift::camera
