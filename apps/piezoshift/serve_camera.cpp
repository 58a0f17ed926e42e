#include "serve_camera.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <new>
#include <utility>

#include <fmt/core.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/host/gcs_client.hpp"
#include "piezoshift/host/gcs_error.hpp"
#include "piezoshift/instrument/measurement.hpp"
#include "piezoshift/instrument/twin_measurement.hpp"
#include "piezoshift/psi/analysis.hpp"
#include "piezoshift/psi/fringe_visibility.hpp"
#include "piezoshift/psi/png_image.hpp"
#include "piezoshift/psi/pupil_detection.hpp"
#include "piezoshift/runtime/safety_supervisor.hpp"
#include "psi_options.hpp"
#include "serve_measure_request.hpp"

namespace piezoshift::app {

namespace {

using Clock = std::chrono::steady_clock;
using nlohmann::json;

// ~20 s of samples at 1 kHz: a camera thread stalled longer (an analysis) keeps the newest.
constexpr std::size_t kMaxIncoming = 20000;
// The live frame's fringe visibility per tile of this side (psi/fringe_visibility.hpp): 8 x 8
// tiles on the twin's 256 px frames, each wider than a fringe of its default surface.
constexpr int kTilePx = 32;
// A preview frame not arrived by then is given up (a real camera that missed the trigger).
constexpr double kPreviewTimeout_s = 2.0;

double now_s() {
  return std::chrono::duration<double>(Clock::now().time_since_epoch()).count();
}

json number(double v) {
  return std::isfinite(v) ? json(v) : json(nullptr);
}

// The modulation map's colour scale: 0 to its robust maximum (as the pupil detection's), so
// that a few hot pixels do not wash it out; 1 for a map without modulation.
double colour_top(const psi::Map& m) {
  const double top = psi::robust_max(m.v);
  return top > 0.0 ? top : 1.0;
}

// "" when MOV?'s answer (Z, U, V) is the pose (z_um, 0, 0) that the measurement commanded, to
// MOV?'s six decimals; otherwise why not.
std::string foreign_target(const std::string& answer, double z_um) {
  const std::vector<std::string> lines = host::GcsClient::split_answer(answer);
  const std::array<double, 3> expected{z_um, 0.0, 0.0};
  bool same = lines.size() == expected.size();
  for (std::size_t i = 0; same && i < lines.size(); ++i) {
    const std::size_t eq = lines[i].find('=');
    same = eq != std::string::npos &&
           std::fabs(std::strtod(lines[i].c_str() + eq + 1, nullptr) - expected[i]) <= 2e-6;
  }
  if (same)
    return {};
  return fmt::format(
      "the stage's targets are {} where this measurement left Z {:.6f} U 0 V 0: "
      "another client's move (or a stop) since",
      fmt::join(lines, " "), z_um);
}

}  // namespace

// A measurement under way: what was asked and the sequence that runs it.
struct ServeCamera::Running {
  Request request;
  instrument::SampleSequence sequence;
};

// The analysis of a finished sequence, as GET /api/measure and the PNGs show it.
struct MeasurementOutcome {
  json j;
  std::string surface_png, modulation_png;
};

namespace {

json steps_json(const instrument::MeasurementAnalysis& a, const instrument::SequenceParams& p) {
  return {{"commanded_rad", p.steps_rad},
          {"recovered_rad", a.recovered_steps_rad},
          {"true_rad", a.true_steps_rad},
          {"worst_error", a.step_error_text()},
          {"reason", a.steps_reason}};
}

// `measure`'s analysis (measure_command.cpp) of a complete, valid sequence. The reason of a
// failure goes into j["reason"] with no surface.
MeasurementOutcome analyse(const instrument::SequenceResult& r, psi::Algorithm algorithm,
                           const instrument::SequenceParams& p,
                           const std::optional<camera::TwinScene>& scene,
                           const std::string& mask_path) {
  MeasurementOutcome out;
  const std::size_t n = p.steps_rad.size();
  const std::vector<psi::Map> frames = instrument::frame_maps(
      std::vector<camera::Frame>(r.frames.begin(), r.frames.begin() + static_cast<long>(n)));
  const psi::Map modulation = psi::modulation_map(frames);
  const double mod_hi = colour_top(modulation);
  out.modulation_png = psi::encode_false_colour_png(modulation, 0.0, mod_hi);
  out.j["modulation"] = {{"unit", "counts"},
                         {"lo", 0.0},
                         {"hi", mod_hi},
                         {"of_average", 0},
                         {"definition", "temporal standard deviation of the frames at each pixel"}};
  psi::Mask mask;
  try {
    mask = scene ? scene->mask : choose_pupil(mask_path, frames, "measurement").mask;
  } catch (const core::InputError& e) {
    out.j["reason"] = e.what();
    return out;
  }
  const psi::AnalysisOptions ao = instrument::measurement_analysis_options(algorithm, p);
  instrument::MeasurementAnalysis a;
  try {
    a = instrument::analyze_measurement(r, p, mask, ao);
  } catch (const std::invalid_argument& e) {
    out.j["reason"] = fmt::format("the frames carry no phase: {}", e.what());
    return out;
  }
  out.j["steps"] = steps_json(a, p);
  if (!a.converged) {
    out.j["reason"] = a.reason;
    return out;
  }
  const auto [lo, hi] = psi::finite_range(a.surface_nm);
  out.surface_png = psi::encode_false_colour_png(a.surface_nm, lo, hi);
  out.j["surface"] = {{"pv_nm", a.figures.pv},
                      {"pvr_nm", a.figures.pvr},
                      {"rms_nm", a.figures.rms},
                      {"pixels", a.figures.pixels},
                      {"lo_nm", lo},
                      {"hi_nm", hi},
                      {"width_px", a.surface_nm.width},
                      {"height_px", a.surface_nm.height}};
  out.j["error_rms_nm"] =
      scene ? number(psi::surface_error_rms_nm(a.surface_nm, scene->surface_nm, a.valid))
            : json(nullptr);
  out.j["valid"] = true;
  return out;
}

}  // namespace

ServeCamera::ServeCamera(std::unique_ptr<camera::Camera> camera,
                         std::optional<camera::TwinScene> scene, host::GcsInterpreter& gcs,
                         std::mutex& gcs_mutex, ServeCameraOptions options)
    : camera_(std::move(camera)),
      scene_(std::move(scene)),
      gcs_(gcs),
      gcs_mutex_(gcs_mutex),
      options_(std::move(options)) {
  if (!options_.preview)
    message_ = fmt::format("camera {}: recorded frames, for measurements only (no live view)",
                           camera_->name());
  const std::lock_guard lock(gcs_mutex_);
  gcs_.on_connect(kSession);
}

ServeCamera::~ServeCamera() {
  stop();
  const std::lock_guard lock(gcs_mutex_);
  gcs_.on_disconnect(kSession);
}

void ServeCamera::start(std::function<void(std::exception_ptr)> on_failure) {
  camera_->start();
  started_ = true;
  thread_ = std::thread([this, on_failure = std::move(on_failure)] {
    // The analysis of a measurement takes a core for a while: it yields to the GCS clients and
    // the dashboard (as the dashboard's thread yields to the GCS clients). Best effort.
    if (::setpriority(PRIO_PROCESS, static_cast<id_t>(::gettid()), 10) != 0) {
    }
    try {
      run();
    } catch (...) {  // only what a failed measurement's own report throws: serve stops, ramped
      if (on_failure)
        on_failure(std::current_exception());
    }
  });
}

void ServeCamera::stop() {
  {
    const std::lock_guard lock(mutex_);
    stop_ = true;
  }
  if (thread_.joinable())
    thread_.join();
  if (started_)
    camera_->stop();
  started_ = false;
}

void ServeCamera::on_sample(const runtime::HostSample& s, const host::RecorderInput& d) {
  instrument::LoopSample ls;
  ls.tick = s.tick;
  ls.t_s = s.t_s;
  for (std::size_t i = 0; i < 3; ++i) {
    ls.gauge_error_nm[i] = 1000.0 * (s.target_um[i] - d.sensor_um[i]);  // S - feedback
    ls.zd_um[i] = s.zd_um[i];
  }
  ls.closed_loop = s.closed_loop != 0;
  ls.overrun = s.overrun != 0;
  ls.faulted = s.state == static_cast<std::uint8_t>(runtime::SupervisorState::kFaulted);
  if (ls.faulted)
    ls.fault = runtime::to_string(static_cast<runtime::FaultReason>(s.fault_reason));
  ls.has_truth = s.has_truth != 0;
  if (ls.has_truth) {
    const host::AxisValues pose = gcs_.model().pose_from_points(s.truth_um);
    // The fringes' piston: the plate's, plus the cavity's drift when the twin puts it there.
    ls.pose = {s.t_s, 1000.0 * pose[0] + s.fringe_drift_nm, pose[1], pose[2]};
  }
  const std::lock_guard lock(mutex_);
  if (incoming_.size() >= kMaxIncoming) {
    const std::size_t half = incoming_.size() / 2;
    incoming_.erase(incoming_.begin(), incoming_.begin() + static_cast<std::ptrdiff_t>(half));
    incoming_dropped_ += half;
  }
  incoming_.push_back(std::move(ls));
}

void ServeCamera::run() {
  std::vector<instrument::LoopSample> batch;
  for (;;) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    bool begin = false;
    {
      const std::lock_guard lock(mutex_);
      if (stop_)
        return;
      batch.clear();
      std::swap(batch, incoming_);
      begin = requested_.has_value() && !running_ && !preview_pending_ && now_s() >= drain_until_s_;
    }
    // A measurement fails alone: whatever it throws (std::bad_alloc, a surface the twin cannot
    // render) ends it with the reason; the thread, the loop and the clients go on.
    if (begin || running_) {
      try {
        step_measurement(begin, batch);
      } catch (const std::exception& e) {
        abandon_measurement(e.what());
      }
      continue;
    }
    try {
      preview(batch);
    } catch (const std::exception& e) {
      preview_pending_ = false;
      const std::lock_guard lock(mutex_);
      message_ = fmt::format("camera {}: the live view failed: {}", camera_->name(), e.what());
    }
  }
}

void ServeCamera::step_measurement(bool begin, const std::vector<instrument::LoopSample>& batch) {
  if (begin)
    begin_measurement();
  for (const instrument::LoopSample& s : batch)
    running_->sequence.feed(s);
  running_->sequence.poll();
  {
    const std::lock_guard lock(mutex_);
    progress_frames_ = running_->sequence.frames_taken();
    progress_total_ = running_->sequence.frames_total();
  }
  if (running_->sequence.done())
    finish_measurement();
}

void ServeCamera::abandon_measurement(const std::string& what) {
  json j = {{"valid", false}, {"camera", camera_->name()}};
  std::size_t frames = 0;
  {
    const std::lock_guard lock(mutex_);
    frames = progress_frames_;  // what it had taken (its result may be taken already)
  }
  if (running_) {
    frames = std::max(frames, running_->sequence.frames_taken());
    j["algorithm"] = psi::algorithm_name(running_->request.algorithm);
    j["averages"] = running_->request.params.averages;
  }
  running_.reset();  // its frames go first: the memory the report needs
  // Its exposures still in flight arrive within a frame timeout; the live view takes them, and
  // the next measurement starts after (else they would be frames no trigger of its asked for).
  drain_until_s_ = now_s() + options_.sequence.frame_timeout_s;
  j["frames"] = frames;
  j["reason"] =
      what == std::bad_alloc().what()
          ? fmt::format("the measurement ran out of memory after {} frames ({})", frames, what)
          : fmt::format("the measurement failed after {} frames: {}", frames, what);
  const std::lock_guard lock(mutex_);
  j["id"] = measurement_id_;
  measurement_json_ = j.dump(-1, ' ', false, json::error_handler_t::replace);  // any bytes
  surface_png_.clear();
  modulation_png_.clear();
  measuring_ = false;
}

void ServeCamera::preview(const std::vector<instrument::LoopSample>& batch) {
  for (const instrument::LoopSample& s : batch) {
    if (!have_origin_ && s.has_truth) {
      origin_ = s.pose;
      have_origin_ = true;
    }
    camera_->observe_plate(camera::relative_to(
        {s.t_s, s.pose.piston_nm, s.pose.theta_x_urad, s.pose.theta_y_urad}, origin_));
    last_t_s_ = s.t_s;
  }
  take_preview_frames();
  const double now = now_s();
  if (preview_pending_ && now - pending_since_s_ > kPreviewTimeout_s) {
    preview_pending_ = false;
    const std::lock_guard lock(mutex_);
    message_ = fmt::format("camera {}: a live frame did not arrive within {} s", camera_->name(),
                           kPreviewTimeout_s);
  }
  const auto now_ns = static_cast<std::uint64_t>(now * 1e9);
  if (!options_.preview || preview_pending_ || last_t_s_ < 0.0 || now_ns < next_preview_ns_)
    return;
  if (camera_->trigger(last_t_s_)) {
    next_preview_ns_ = now_ns + static_cast<std::uint64_t>(options_.preview_period_s * 1e9);
    preview_pending_ = true;
    pending_since_s_ = now;
    refused_since_s_ = -1.0;
    return;
  }
  // Refused: tried again with the next batch. Right after a measurement the camera still reads
  // out its last frame (10 ms): only a refusal that lasts is news.
  if (refused_since_s_ < 0.0)
    refused_since_s_ = now;
  if (now - refused_since_s_ > kPreviewTimeout_s) {
    const std::lock_guard lock(mutex_);
    message_ = fmt::format("camera {} has taken no live trigger for {} s: {}", camera_->name(),
                           kPreviewTimeout_s, camera_->message());
  }
}

void ServeCamera::take_preview_frames() {
  for (;;) {
    camera::Frame f;
    const camera::FrameStatus st = camera_->poll(f);
    if (st == camera::FrameStatus::kNone)
      return;
    preview_pending_ = false;
    if (st == camera::FrameStatus::kOk) {
      publish_frame(f);
      continue;
    }
    const std::lock_guard lock(mutex_);
    message_ = fmt::format("camera {}: live frame {}: {} ({})", camera_->name(), f.frame_id,
                           camera::to_string(st), camera_->message());
  }
}

void ServeCamera::publish_frame(const camera::Frame& f) {
  const double full = std::exp2(camera::bit_depth(f.format)) - 1.0;
  psi::Map counts(f.width_px, f.height_px);
  psi::Map scaled(f.width_px, f.height_px);  // full scale at 65535: the PNG shows it white
  std::size_t saturated = 0;
  double max_counts = 0.0, sum = 0.0;
  for (std::size_t p = 0; p < f.counts.size() && p < counts.size(); ++p) {
    const double c = f.counts[p];
    counts.v[p] = c;
    scaled.v[p] = c * 65535.0 / full;
    saturated += c >= full ? 1 : 0;
    max_counts = std::max(max_counts, c);
    sum += c;
  }
  const psi::FringeVisibility vis = psi::fringe_visibility(counts, full, kTilePx);
  const double pixels = static_cast<double>(std::max<std::size_t>(counts.size(), 1));
  json j = {{"id", f.frame_id},
            {"trigger_time_s", f.trigger_time_s},
            {"width_px", f.width_px},
            {"height_px", f.height_px},
            {"bits", camera::bit_depth(f.format)},
            {"full_scale_counts", full},
            {"max_counts", max_counts},
            {"mean_counts", sum / pixels},
            {"saturated_pixels", saturated},
            {"saturated_fraction", static_cast<double>(saturated) / pixels},
            {"exposure_s", f.exposure_s},
            {"visibility",
             {{"median", number(vis.median)},
              {"p90", number(vis.p90)},
              {"tiles_judged", vis.judged},
              {"tile_px", kTilePx},
              {"definition",
               "(I98 - I2) / (I98 + I2) per 32 px tile, I98 and I2 the 98th and "
               "2nd percentiles of its counts; dark tiles (outside the pupil) "
               "left out"}}}};
  std::string frame_png = psi::encode_png_gray16(scaled);
  // Each tile drawn over its pixels, so that the map lies over the frame (and its scale bar
  // has the frame's height).
  psi::Map vis_px(f.width_px, f.height_px);
  for (int y = 0; y < f.height_px; ++y)
    for (int x = 0; x < f.width_px; ++x)
      vis_px.at(x, y) = vis.tiles.at(x / kTilePx, y / kTilePx);
  std::string vis_png = psi::encode_false_colour_png(vis_px, 0.0, 1.0);
  const std::lock_guard lock(mutex_);
  if (options_.preview)
    message_.clear();  // the camera works again
  frame_png_ = std::move(frame_png);
  visibility_png_ = std::move(vis_png);
  frame_json_ = j.dump();
}

std::string ServeCamera::move(double z_um) {
  const std::lock_guard lock(gcs_mutex_);
  const auto error = [this]() { return std::stoi(gcs_.on_line(kSession, "ERR?")); };
  // Errors queued before (a fault's -1024) are not this move's.
  for (int i = 0; i < 32 && error() != 0; ++i) {
  }
  const auto run = [&](const std::string& line) -> std::string {
    gcs_.on_line(kSession, line);
    const int code = error();
    if (code == 0)
      return {};
    return fmt::format("`{}`: GCS error {}, {}", line, code,
                       host::describe(static_cast<host::GcsError>(code)));
  };
  if (commanded_z_um_) {
    // A target other than the one this measurement left is another client's move that the loop
    // may never have shown (both applied in one tick): ours would silently undo it.
    const std::string why = foreign_target(gcs_.on_line(kSession, "MOV? Z U V"), *commanded_z_um_);
    if (!why.empty())
      return why;
  }
  commanded_z_um_ = z_um;
  const std::vector<std::string> servo =
      host::GcsClient::split_answer(gcs_.on_line(kSession, "SVO?"));
  if (servo.empty() || servo.front() != "Z=1")
    if (std::string why = run("SVO Z 1 U 1 V 1"); !why.empty())
      return why;
  return run(fmt::format("MOV Z {:.9f} U 0 V 0", z_um));
}

void ServeCamera::begin_measurement() {
  Request req;
  {
    const std::lock_guard lock(mutex_);
    req = std::move(*requested_);
    requested_.reset();
  }
  // A live frame that arrived since is not the measurement's.
  for (camera::Frame f; camera_->poll(f) != camera::FrameStatus::kNone;) {
  }
  const instrument::SequenceParams params = req.params;
  commanded_z_um_.reset();
  running_ = std::make_unique<Running>(Running{
      std::move(req), instrument::SampleSequence(*camera_, params, options_.period_s,
                                                 [this](double z_um) { return move(z_um); })});
}

void ServeCamera::finish_measurement() {
  instrument::SequenceResult r = running_->sequence.take();
  const Request& req = running_->request;
  if (!r.validity.valid)  // as a measurement that threw: its frames in flight come first
    drain_until_s_ = now_s() + options_.sequence.frame_timeout_s;
  if (!options_.preview && !r.frames.empty())
    publish_frame(r.frames.front());  // no live view: the measurement's first frame instead
  MeasurementOutcome out;
  if (r.validity.valid)
    out = analyse(r, req.algorithm, req.params, scene_, options_.mask);
  else
    out.j["reason"] = r.validity.reason;
  json& j = out.j;
  if (!j.contains("valid"))
    j["valid"] = false;
  if (!j.contains("reason"))
    j["reason"] = "";
  j["algorithm"] = psi::algorithm_name(req.algorithm);
  j["averages"] = req.params.averages;
  j["frames"] = r.frames.size();
  j["camera"] = camera_->name();
  j["wall_time_s"] = r.wall_time_s;
  j["loop_time_s"] = r.loop_time_s;
  j["floor_s"] = r.floor_s;
  j["overruns"] = r.overruns;
  if (!j["valid"].get<bool>()) {
    out.surface_png.clear();  // a failed measurement shows its reason, never a surface
    j.erase("surface");
  }
  running_.reset();
  const std::lock_guard lock(mutex_);
  j["id"] = measurement_id_;
  measurement_json_ = j.dump();
  surface_png_ = std::move(out.surface_png);
  modulation_png_ = std::move(out.modulation_png);
  measuring_ = false;
}

host::HttpResponse ServeCamera::png(const std::string& bytes, const char* missing) const {
  if (bytes.empty())
    return host::HttpResponse::text(409, missing);
  host::HttpResponse r;
  r.content_type = "image/png";
  r.body = bytes;
  return r;
}

host::HttpResponse ServeCamera::measure_post(const host::HttpRequest& request) {
  MeasureRequestContext context;
  context.sequence = options_.sequence;
  context.travel_z_max_um = options_.travel_z_max_um;
  context.calibration_source = options_.calibration_source;
  context.camera = camera_->settings();
  MeasureRequestCheck check = check_measure_request(request.body, context);
  if (check.status != 200)
    return host::HttpResponse::text(check.status, check.reason);
  Request req = std::move(check.request);
  const std::lock_guard lock(mutex_);
  if (measuring_)
    return host::HttpResponse::text(
        409, fmt::format("measurement {} is running ({} of {} frames taken): wait for it to end",
                         measurement_id_, progress_frames_, progress_total_));
  requested_ = std::move(req);
  measuring_ = true;
  progress_frames_ = 0;
  progress_total_ = 0;
  ++measurement_id_;
  return host::HttpResponse::json(200, json{{"id", measurement_id_}, {"running", true}}.dump());
}

host::HttpResponse ServeCamera::on_request(const host::HttpRequest& request) {
  const std::string& path = request.path;
  if (path == "/api/measure" && request.method == "POST")
    return measure_post(request);
  if (request.method != "GET")
    return host::HttpResponse::text(405, path == "/api/measure" ? "GET or POST" : "GET only");
  if (path == "/api/camera") {
    const camera::CameraSettings& cs = camera_->settings();
    const std::lock_guard lock(mutex_);
    return host::HttpResponse::json(
        200, fmt::format(R"({{"camera":{},"width_px":{},"height_px":{},"bits":{},)"
                         R"("exposure_s":{},"preview_period_s":{},"preview":{},"measuring":{},)"
                         R"("message":{},"samples_dropped":{},"frame":{}}})",
                         json(camera_->name()).dump(), cs.width_px, cs.height_px,
                         camera::bit_depth(cs.format), cs.exposure_s, options_.preview_period_s,
                         options_.preview, measuring_, json(message_).dump(), incoming_dropped_,
                         frame_json_));
  }
  if (path == "/api/measure") {
    const std::lock_guard lock(mutex_);
    return host::HttpResponse::json(
        200, fmt::format(R"({{"running":{},"id":{},"progress":{{"frames":{},"of":{}}},"last":{}}})",
                         measuring_, measurement_id_, progress_frames_, progress_total_,
                         measurement_json_));
  }
  std::string bytes;
  const char* missing = "";
  {
    const std::lock_guard lock(mutex_);
    if (path == "/api/camera/frame.png") {
      bytes = frame_png_;
      missing = "no live frame yet";
    } else if (path == "/api/camera/visibility.png") {
      bytes = visibility_png_;
      missing = "no live frame yet";
    } else if (path == "/api/measure/surface.png") {
      bytes = surface_png_;
      missing =
          "no surface: no measurement yet, or the last one failed (GET /api/measure says why)";
    } else if (path == "/api/measure/modulation.png") {
      bytes = modulation_png_;
      missing = "no modulation map: no measurement has taken its frames yet";
    } else {
      return host::HttpResponse::text(404, fmt::format("no such page: {}", path));
    }
  }
  return png(bytes, missing);
}

}  // namespace piezoshift::app
