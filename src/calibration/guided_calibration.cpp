#include "piezoshift/calibration/guided_calibration.hpp"

#include <cmath>
#include <optional>

#include <fmt/core.h>
#include <Eigen/Dense>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/rig/validity.hpp"

namespace piezoshift::calibration {

namespace {

constexpr Optics kPoints[3] = {Optics::kP1, Optics::kP2, Optics::kP3};
constexpr double kPoseSlack_um = 0.05;
constexpr double kLevelSlack_um = 0.3;

Vec3 solve(const control::Mat3& a, const Vec3& b) {
  Eigen::Matrix3d m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      m(r, c) = a[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)];
  const Eigen::Vector3d x = m.colPivHouseholderQr().solve(Eigen::Vector3d(b[0], b[1], b[2]));
  return Vec3{x[0], x[1], x[2]};
}

std::size_t index_of(Optics o) {
  return o == Optics::kP2 ? 1 : o == Optics::kP3 ? 2 : 0;
}

std::string instruction(const GuidedStep& s) {
  if (s.stage == 2)
    return fmt::format(
        "stage 2 (matrix A): put the interferometer's optics on measurement point {} "
        "(the readings are differences: the datum does not matter)\n",
        to_string(s.optics));
  return "stage 3 (polynomial p): put the optics at the centre (the centroid of P1, P2, P3); the "
         "stage is at rest at 0 V: zero the interferometer now, before the first reading\n";
}

// Why the reading is implausible, or nothing.
std::optional<std::string> check(const std::vector<GuidedStep>& plan, const GuidedSession& session,
                                 std::size_t k, double reading, const rig::RigWindow& w,
                                 const control::Mat3& a0, const GuidedOptions& o) {
  const GuidedStep& s = plan[k];
  if (s.stage == 2 && !s.moved) {
    // The previous base reading at this point (same session of the optics).
    for (std::size_t j = k; j-- > 0;) {
      if (plan[j].stage != 2 || plan[j].optics != s.optics)
        break;
      if (plan[j].moved)
        continue;
      const double drift = reading - *session.readings[j].reading_um;
      if (std::fabs(drift) > o.max_zero_drift_um)
        return fmt::format(
            "{:.4f} um at the base pose differs by {:+.4f} um from the base reading {:.4f} um "
            "before it (at most {:g} um of drift): did the optics or the datum move?",
            reading, drift, *session.readings[j].reading_um, o.max_zero_drift_um);
      return std::nullopt;
    }
    return std::nullopt;
  }
  if (s.stage == 2) {
    const SessionReading& b = session.readings[k - 1];
    Vec3 ds{};
    for (std::size_t i = 0; i < 3; ++i)
      ds[i] = w.sgs_um[i] - b.sgs_um[i];
    const double expected = solve(a0, ds)[index_of(s.optics)];
    const double dz = reading - *b.reading_um;
    const double tol = o.pose_tolerance_fraction * o.matrix.move_um + kPoseSlack_um;
    if (std::fabs(dz - expected) > tol)
      return fmt::format(
          "{:.4f} um is a move of {:+.4f} um from the base reading {:.4f} um; actuator {} moving "
          "by {:g} um should move {} by about {:+.3f} um (within {:.2f} um): check the sign, "
          "the unit (um) and the optics' position",
          reading, dz, *b.reading_um, s.actuator + 1, o.matrix.move_um, to_string(s.optics),
          expected, tol);
    return std::nullopt;
  }
  const double tol = o.level_tolerance_fraction * s.command_um + kLevelSlack_um;
  if (std::fabs(reading - s.command_um) > tol)
    return fmt::format(
        "{:.4f} um at the command {:g} um is off by more than {:.2f} um: check the unit (um), "
        "the optics' position and that the interferometer was zeroed at rest",
        reading, s.command_um, tol);
  for (std::size_t j = k; j-- > 0 && plan[j].stage == 3;) {
    if (const auto& prev = session.readings[j].reading_um) {
      if (!(reading > *prev))
        return fmt::format(
            "{:.4f} um is not above the reading {:.4f} um at the command {:g} um "
            "before it: the stage moves up",
            reading, *prev, plan[j].command_um);
      break;
    }
  }
  return std::nullopt;
}

MatrixIdentificationResult fit_stage2(const GuidedSession& session, const GuidedOptions& o) {
  // Pose (rep, i): dZ_j from the session at P_j; dS the mean of the three sessions' differences.
  MatrixIdentificationResult r;
  const auto per_point = static_cast<std::size_t>(o.matrix.repeats) * 3;
  for (std::size_t p = 0; p < per_point; ++p) {
    Vec3 ds{}, dz{};
    for (std::size_t j = 0; j < 3; ++j) {
      const std::size_t base = 2 * (j * per_point + p);
      const SessionReading& b = session.readings[base];
      const SessionReading& m = session.readings[base + 1];
      for (std::size_t i = 0; i < 3; ++i)
        ds[i] += (m.sgs_um[i] - b.sgs_um[i]) / 3.0;
      dz[j] = *m.reading_um - *b.reading_um;
    }
    r.ds_um.push_back(ds);
    r.dz_um.push_back(dz);
  }
  r.fit = fit_transmission_matrix(r.ds_um, r.dz_um);
  return r;
}

}  // namespace

std::vector<GuidedStep> guided_plan(const GuidedOptions& o) {
  if (!(o.matrix.repeats >= 1) || !(o.matrix.move_um > 0.0) || !(o.matrix.base_um >= 0.0) ||
      !(o.matrix.settle_s >= 0.0) || o.polynomial.points < kPolyFitMinPoints ||
      !(o.polynomial.max_um > 0.0) || !(o.polynomial.settle_s >= 0.0))
    throw std::invalid_argument("guided calibration: bad stage options");
  std::vector<GuidedStep> plan;
  const Vec3 base{o.matrix.base_um, o.matrix.base_um, o.matrix.base_um};
  for (Optics optics : kPoints) {
    for (int rep = 0; rep < o.matrix.repeats; ++rep) {
      for (std::size_t i = 0; i < 3; ++i) {
        GuidedStep s;
        s.optics = optics;
        s.repeat = rep;
        s.actuator = i;
        s.setpoint_um = base;
        plan.push_back(s);
        s.moved = true;
        s.setpoint_um[i] += o.matrix.move_um;
        plan.push_back(s);
      }
    }
  }
  for (std::size_t k = 0; k < o.polynomial.points; ++k) {
    GuidedStep s;
    s.stage = 3;
    s.optics = Optics::kCentre;
    s.command_um =
        o.polynomial.max_um * static_cast<double>(k) / static_cast<double>(o.polynomial.points - 1);
    s.setpoint_um = Vec3{s.command_um, s.command_um, s.command_um};
    plan.push_back(s);
  }
  return plan;
}

std::string describe(const GuidedStep& s, const GuidedOptions& o) {
  if (s.stage == 3)
    return fmt::format("stage 3, command {:g} um at P1..P3", s.command_um);
  return fmt::format(
      "stage 2, optics at {}, repeat {}, {}", to_string(s.optics), s.repeat + 1,
      s.moved ? fmt::format("actuator {} moved by {:g} um", s.actuator + 1, o.matrix.move_um)
              : fmt::format("base pose (all at {:g} um) before actuator {}", o.matrix.base_um,
                            s.actuator + 1));
}

GuidedOutcome run_guided_calibration(rig::GuidedRig& stage2, rig::GuidedRig& stage3,
                                     const control::SemiClosedLoopParams& base,
                                     GuidedSession& session, GuidedIo& io, const GuidedOptions& o) {
  const std::vector<GuidedStep> plan = guided_plan(o);
  if (session.steps != plan.size())
    throw std::invalid_argument("guided calibration: the session is for another plan");
  // A base reading without its moved reading is half a pose: take the pair again.
  if (!session.readings.empty()) {
    const GuidedStep& last = plan[session.readings.size() - 1];
    if (last.stage == 2 && !last.moved)
      session.readings.pop_back();
  }
  const std::size_t recorded = session.readings.size();
  const control::Mat3 a0 = base.matrix.a;

  GuidedOutcome out;
  out.controller = base;
  control::SemiClosedLoopParams inner = base;
  inner.matrix = control::TransmissionMatrix::identity();
  inner.polynomial = control::CubicPolynomial::identity();
  stage2.set_controller(inner);

  const auto fail_on_fault = [](const rig::GuidedRig& driven, int stage) {
    const std::string f = driven.fault();
    if (!f.empty())
      throw rig::ProcedureFailed(fmt::format("calibration stage {} ({}): {}", stage,
                                             stage == 2 ? "matrix A" : "polynomial p", f));
  };

  for (std::size_t k = 0; k < plan.size(); ++k) {
    const GuidedStep& s = plan[k];
    rig::GuidedRig& driven = s.stage == 2 ? stage2 : stage3;
    const bool first_of_stage3 = s.stage == 3 && plan[k - 1].stage == 2;  // stage 2 comes first
    if (first_of_stage3) {
      out.matrix = fit_stage2(session, o);
      out.controller.matrix = out.matrix.fit.a;
      control::SemiClosedLoopParams p = out.controller;
      p.polynomial = control::CubicPolynomial::identity();
      stage3.set_controller(p);
    }
    const bool taking = k >= recorded;
    if (!taking && !driven.replays())
      continue;
    const bool new_position = k == 0 || plan[k - 1].optics != s.optics || k == recorded;
    if (taking && new_position)
      io.say(instruction(s));
    if (first_of_stage3)
      driven.rest(o.polynomial.settle_s);
    if (s.stage == 2)
      driven.drive_actuators(s.setpoint_um);
    else
      driven.drive_points(s.setpoint_um);
    driven.settle(s.stage == 2 ? o.matrix.settle_s : o.polynomial.settle_s);
    const rig::RigWindow w = driven.measure();
    fail_on_fault(driven, s.stage);
    if (!taking)
      continue;

    SessionReading e;
    e.step = k;
    e.optics = to_string(s.optics);
    e.sgs_um = w.sgs_um;
    e.window_start_s = w.start_s;
    e.window_end_s = w.end_s;
    e.saturated = w.saturated;
    if (s.stage == 3 && w.saturated) {
      io.say(
          fmt::format("command {:g} um: a PID is at its output limit, not a tracked point: "
                      "skipped, no reading needed\n",
                      s.command_um));
    } else {
      ReadingRequest req{k, plan.size(), s.optics, describe(s, o), w};
      for (;;) {
        const std::optional<double> v = io.source.read(req);
        if (!v)
          return out;
        const std::optional<std::string> why = check(plan, session, k, *v, w, a0, o);
        if (!why) {
          e.reading_um = *v;
          break;
        }
        if (!io.source.can_retry())
          throw core::InputError(fmt::format("{}: reading {} ({}) refused: {}", io.source.name(),
                                             k + 1, req.what, *why));
        io.source.refuse(*why);
      }
    }
    session.readings.push_back(e);
    ++out.taken;
    io.record(session);
  }
  PolynomialIdentificationResult& pr = out.polynomial;
  for (std::size_t k = 0; k < plan.size(); ++k) {
    if (plan[k].stage != 3)
      continue;
    if (const auto& v = session.readings[k].reading_um) {
      pr.command_um.push_back(plan[k].command_um);
      pr.measured_um.push_back(*v);
    } else {
      ++pr.saturated_points;
    }
  }
  pr.fit = fit_cubic_polynomial(pr.measured_um, pr.command_um);
  out.controller.polynomial = pr.fit.p;
  out.complete = true;
  return out;
}

}  // namespace piezoshift::calibration
