#pragma once
// `serve --camera`: the camera's live view and the measurements started from the dashboard
// (docs/dashboard.md), a host::DashboardPanel with a thread of its own, the camera thread.
//
//   samples     on_sample (GCS thread, GCS mutex held) turns each HostSample into an
//               instrument::LoopSample (S - feedback from the SGS, the plate's true pose from
//               the twin's P1..P3 through the stage model, as the dashboard's truth) and queues
//               it under this panel's own mutex, a copy and nothing more
//   preview     the camera thread takes the queue every 2 ms; every sample's pose goes to the
//               camera (observe_plate; the twin camera renders from it), and every
//               preview_period_s it triggers one exposure at the loop time of the newest sample
//               (free-running; never while a measurement runs). A frame that arrives is turned
//               into a PNG, its saturation and its fringe visibility (psi/fringe_visibility.hpp)
//               on this thread; the HTTP thread copies them out under the short lock
//   measurement POST /api/measure {"algorithm": "hariharan5", "averages": 1} starts one
//               (409 while one runs); the camera thread runs instrument::SampleSequence on the
//               samples, its moves as GCS lines (SVO on if off, MOV Z z U 0 V 0) on a session of
//               its own, then the analysis of `measure` (instrument::analyze_measurement). Other
//               clients are not locked out: a move of theirs, a wave, a stop or SVO 0 while it
//               runs fails the measurement with that reason (sample_sequence.hpp). GET
//               /api/measure says how it went; the surface and the modulation map of the last
//               valid one as PNGs; a failed one has its reason and no surface
// Nothing here runs on the loop's thread; the HTTP thread never waits for the camera.
#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "piezoshift/camera/camera.hpp"
#include "piezoshift/camera/twin_camera.hpp"
#include "piezoshift/host/dashboard_panel.hpp"
#include "piezoshift/host/gcs_interpreter.hpp"
#include "piezoshift/host/stage_model.hpp"
#include "piezoshift/instrument/sample_sequence.hpp"
#include "serve_measure_request.hpp"

namespace piezoshift::app {

struct ServeCameraOptions {
  double period_s = 1e-3;          //!< the loop's
  double preview_period_s = 0.25;  //!< 4 live frames per second
  //! false: no live frames (files:DIR, whose recorded frames are the measurements' own)
  bool preview = true;
  std::string mask;  //!< the pupil as a PNG for cameras other than the twin ("" : from the frames)
  instrument::SequenceParams sequence;  //!< base, settle criterion, timeouts (steps per request)
  std::optional<double> travel_z_max_um;
  std::string calibration_source;
};

class ServeCamera final : public host::DashboardPanel {
 public:
  //! camera: configured, not started. scene: the twin camera's (its mask and truth). gcs and
  //! gcs_mutex: serve's interpreter, on which the panel opens a session of its own.
  ServeCamera(std::unique_ptr<camera::Camera> camera, std::optional<camera::TwinScene> scene,
              host::GcsInterpreter& gcs, std::mutex& gcs_mutex, ServeCameraOptions options);
  ~ServeCamera() override;
  ServeCamera(const ServeCamera&) = delete;
  ServeCamera& operator=(const ServeCamera&) = delete;

  //! Starts the camera and the camera thread; stop() joins it (also in the destructor). A
  //! measurement or a live frame that throws fails alone (its reason in GET /api/measure or
  //! /api/camera); on_failure gets only what escapes that (the thread has ended then).
  void start(std::function<void(std::exception_ptr)> on_failure = {});
  void stop();
  std::thread& thread() { return thread_; }

  host::HttpResponse on_request(const host::HttpRequest& request) override;
  void on_sample(const runtime::HostSample& sample, const host::RecorderInput& derived) override;

  //! The GCS session of the measurements; never a LineServer client id nor the dashboard's.
  static constexpr host::ClientId kSession = ~host::ClientId{0} - 1;

 private:
  using Request = MeasureRequest;
  struct Running;

  void run();
  void preview(const std::vector<instrument::LoopSample>& batch);
  void take_preview_frames();
  void publish_frame(const camera::Frame& frame);
  void step_measurement(bool begin, const std::vector<instrument::LoopSample>& batch);
  void begin_measurement();
  void finish_measurement();
  //! Ends the running measurement (if any) as failed, with what.
  void abandon_measurement(const std::string& what);
  std::string move(double z_um);
  host::HttpResponse measure_post(const host::HttpRequest& request);
  host::HttpResponse png(const std::string& bytes, const char* missing) const;

  std::unique_ptr<camera::Camera> camera_;
  std::optional<camera::TwinScene> scene_;
  host::GcsInterpreter& gcs_;
  std::mutex& gcs_mutex_;
  ServeCameraOptions options_;
  std::thread thread_;
  bool started_ = false;

  // Shared between the threads, under mutex_ (held only to copy in or out).
  mutable std::mutex mutex_;
  std::vector<instrument::LoopSample> incoming_;
  std::uint64_t incoming_dropped_ = 0;
  std::string frame_png_, frame_json_ = "null", visibility_png_;
  std::string message_;
  std::optional<Request> requested_;
  bool measuring_ = false;
  std::uint64_t measurement_id_ = 0;
  std::size_t progress_frames_ = 0, progress_total_ = 0;
  std::string measurement_json_ = "null", surface_png_, modulation_png_;
  bool stop_ = false;

  // The camera thread's own.
  std::unique_ptr<Running> running_;
  std::optional<double> commanded_z_um_;  //!< the running measurement's last move
  camera::PlatePose origin_{};
  bool have_origin_ = false;
  bool preview_pending_ = false;
  double last_t_s_ = -1.0;
  double pending_since_s_ = 0.0;
  double refused_since_s_ = -1.0;  //!< live triggers refused since (-1: the last was taken)
  std::uint64_t next_preview_ns_ = 0;
  double drain_until_s_ = 0.0;  //!< a failed measurement's frames may arrive until then
};

}  // namespace piezoshift::app
