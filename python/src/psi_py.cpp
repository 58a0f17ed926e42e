// Python bindings of the psi module (docs/psi.md): frames, masks and maps as numpy arrays.
//   frames: (N, H, W) float array (any numeric dtype is converted); mask: (H, W), nonzero inside
//   (None: psi_analyze finds the pupil from the fringe modulation; the others take the whole
//   frame). Maps come back as (H, W) float64 arrays with NaN outside the mask.
// Results are dicts with the JSON names of `piezoshift psi analyze`.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "bindings.hpp"
#include "piezoshift/config/project_config.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/core/wavelength.hpp"
#include "piezoshift/psi/analysis.hpp"
#include "piezoshift/psi/pupil_detection.hpp"
#include "piezoshift/psi/simulation.hpp"
#include "piezoshift/psi/unwrap.hpp"
#include "piezoshift/psi/zernike.hpp"

namespace py = pybind11;
namespace psi = piezoshift::psi;

namespace {

using In = py::array_t<double, py::array::c_style | py::array::forcecast>;

py::array_t<double> to_numpy(const psi::Map& m) {
  py::array_t<double> a({static_cast<py::ssize_t>(m.height), static_cast<py::ssize_t>(m.width)});
  std::copy(m.v.begin(), m.v.end(), a.mutable_data());
  return a;
}

psi::Map map_from(const In& a, const char* name) {
  if (a.ndim() != 2)
    throw piezoshift::core::InputError(std::string(name) + ": expected a 2-D array");
  psi::Map m(static_cast<int>(a.shape(1)), static_cast<int>(a.shape(0)));
  std::copy(a.data(), a.data() + a.size(), m.v.begin());
  return m;
}

std::vector<psi::Map> frames_from(const In& a) {
  if (a.ndim() != 3 || a.shape(0) < 3)
    throw piezoshift::core::InputError("frames: expected an (N, H, W) array with N >= 3");
  const auto h = a.shape(1), w = a.shape(2);
  if (h < 1 || w < 1 || h > 2048 || w > 2048)
    throw piezoshift::core::InputError("frames: each side 1..2048 pixels");
  std::vector<psi::Map> frames;
  for (py::ssize_t k = 0; k < a.shape(0); ++k) {
    psi::Map m(static_cast<int>(w), static_cast<int>(h));
    std::copy(a.data() + k * h * w, a.data() + (k + 1) * h * w, m.v.begin());
    frames.push_back(std::move(m));
  }
  return frames;
}

psi::Mask mask_from(const py::object& o, int w, int h) {
  if (o.is_none())
    return psi::Mask(w, h, 1);
  const psi::Map m = map_from(o.cast<In>(), "mask");
  if (m.width != w || m.height != h)
    throw piezoshift::core::InputError("mask: not the frames' size");
  psi::Mask mask(w, h, 0);
  for (std::size_t p = 0; p < m.size(); ++p)
    mask.v[p] = m.v[p] != 0.0 ? 1 : 0;
  return mask;
}

// The pupil analysed: the mask given, else the one found from the frames' fringe modulation
// (pupil_detection.hpp), as `psi analyze` does without --mask.
std::pair<psi::Mask, py::dict> pupil_from(const py::object& o,
                                          const std::vector<psi::Map>& frames) {
  py::dict d;
  psi::Mask mask;
  if (o.is_none()) {
    try {
      mask = psi::pupil_from_modulation(frames).mask;
    } catch (const std::invalid_argument& e) {
      throw piezoshift::core::InputError(std::string("psi: ") + e.what());
    }
    d["source"] = "modulation";
  } else {
    mask = mask_from(o, frames[0].width, frames[0].height);
    d["source"] = "mask";
  }
  d["pixels"] = mask.count();
  psi::Map m(mask.width, mask.height);
  for (std::size_t q = 0; q < m.size(); ++q)
    m.v[q] = mask.v[q];
  d["mask"] = to_numpy(m);
  return {std::move(mask), d};
}

// A fit that did not converge (aia, tilt-aia) returns no surface: surface_nm and phase_rad are
// None, reason says why.
py::dict analysis_dict(const psi::Analysis& a, psi::Algorithm alg) {
  py::dict d;
  d["algorithm"] = std::string(psi::algorithm_name(alg));
  d["converged"] = a.phase.converged;
  d["reason"] = a.phase.reason;
  d["residual_rms"] = a.phase.residual_rms;
  d["noise_rms"] = a.phase.noise_rms;
  d["surface_nm"] = a.phase.converged ? py::object(to_numpy(a.surface_nm)) : py::none();
  d["phase_rad"] = a.phase.converged ? py::object(to_numpy(a.phase.phase_rad)) : py::none();
  d["steps_rad"] = a.phase.steps_rad;
  d["step_conditioning"] = a.phase.step_conditioning;  // aia, else NaN
  d["iterations"] = a.phase.iterations;
  d["surface_rms_nm"] = a.figures.rms;
  d["surface_pv_nm"] = a.figures.pv;
  d["surface_pvr_nm"] = a.figures.pvr;
  d["zernike_nm"] = a.zernike_nm;
  if (!a.phase.shifts.empty()) {
    const psi::FrameShiftColumns c = psi::shift_columns(a.phase.shifts);
    d["piston_rad"] = c.piston_rad;
    d["tip_rad"] = c.tip_rad;
    d["tilt_rad"] = c.tilt_rad;
  }
  return d;
}

psi::Analysis analyze(const std::vector<psi::Map>& frames, const psi::Mask& mask,
                      const psi::AnalysisOptions& o) {
  try {
    return psi::analyze_frames(frames, mask, o);
  } catch (const std::invalid_argument& e) {
    throw piezoshift::core::InputError(std::string("psi: ") + e.what());
  }
}

}  // namespace

namespace piezoshift::python {

void bind_psi(py::module_& m) {
  m.def(
      "psi_analyze",
      [](const In& frames_in, const py::object& mask_in, const std::string& algorithm,
         const std::vector<double>& steps_rad, double wavelength_nm, bool remove_power) {
        const std::vector<psi::Map> frames = frames_from(frames_in);
        const auto [mask, pupil] = pupil_from(mask_in, frames);
        psi::AnalysisOptions o;
        o.phase.algorithm = psi::parse_algorithm(algorithm);
        const int need = psi::required_frames(o.phase.algorithm);
        if (need > 0 && static_cast<std::size_t>(need) != frames.size())
          throw piezoshift::core::InputError(algorithm + " needs " + std::to_string(need) +
                                             " frames");
        o.phase.steps_rad = steps_rad;
        o.wavelength_nm = wavelength_nm;
        o.removal = remove_power ? psi::Removal::kTiltAndPower : psi::Removal::kTilt;
        py::dict d = analysis_dict(analyze(frames, mask, o), o.phase.algorithm);
        d["pupil"] = pupil;
        return d;
      },
      py::arg("frames"), py::arg("mask") = py::none(), py::arg("algorithm") = "hariharan5",
      py::arg("steps_rad") = std::vector<double>{},
      py::arg("wavelength_nm") = piezoshift::core::kHeNeWavelength_nm,
      py::arg("remove_power") = false,
      "Frames (N, H, W) to a surface map [nm] and its figures (docs/psi.md); mask None: the "
      "pupil found from the fringe modulation");

  m.def(
      "psi_simulate",
      [](const piezoshift::config::ProjectConfig& config,
         const piezoshift::control::SemiClosedLoopParams& controller, const std::string& algorithm,
         int size_px, std::uint64_t seed, const std::string& surface) {
        psi::SimulationParams p;
        p.algorithm = psi::parse_algorithm(algorithm);
        if (size_px < 32 || size_px > 2048)
          throw piezoshift::core::InputError("size_px: must be in 32..2048");
        p.fizeau.width_px = p.fizeau.height_px = size_px;
        p.fizeau.pupil_radius_px = 0.47 * size_px;
        p.seed = seed;
        if (!surface.empty())
          p.surface = psi::parse_surface_spec(surface);
        const psi::SimulationResult r = psi::simulate_psi(config, controller, p);
        py::dict d = analysis_dict(r.analysis, p.algorithm);
        py::array_t<double> frames({static_cast<py::ssize_t>(r.frames.size()),
                                    static_cast<py::ssize_t>(size_px),
                                    static_cast<py::ssize_t>(size_px)});
        double* out = frames.mutable_data();
        for (const psi::Map& f : r.frames)
          out = std::copy(f.v.begin(), f.v.end(), out);
        d["frames"] = frames;
        psi::Map mask(r.mask.width, r.mask.height);
        for (std::size_t q = 0; q < mask.size(); ++q)
          mask.v[q] = r.mask.v[q];
        d["mask"] = to_numpy(mask);
        d["truth_nm"] = to_numpy(r.truth_nm);
        d["surface_error_rms_nm"] = r.error_rms_nm;
        d["ideal_stage_error_rms_nm"] = r.ideal_error_rms_nm;
        d["stage_error_rms_nm"] = r.stage_error_rms_nm;
        std::vector<double> step_nm;
        for (const psi::FrameStats& s : r.frame_stats)
          step_nm.push_back(s.step_nm);
        d["stage_step_nm"] = step_nm;
        return d;
      },
      py::arg("config"), py::arg("controller"), py::arg("algorithm") = "hariharan5",
      py::arg("size_px") = 128, py::arg("seed") = 1, py::arg("surface") = "",
      "The PSI acquisition on the twin, rendered, analysed and compared with the truth");

  m.def(
      "psi_unwrap",
      [](const In& wrapped, const py::object& mask_in) {
        const psi::Map w = map_from(wrapped, "wrapped");
        return to_numpy(psi::unwrap_phase(w, mask_from(mask_in, w.width, w.height)));
      },
      py::arg("wrapped"), py::arg("mask") = py::none(), "Quality-guided masked unwrapping [rad]");

  m.def(
      "zernike_fit",
      [](const In& surface, const py::object& mask_in, int terms) {
        const psi::Map s = map_from(surface, "surface");
        psi::Mask mask = mask_from(mask_in, s.width, s.height);
        try {
          return psi::fit_zernike(s, mask, terms);
        } catch (const std::invalid_argument& e) {
          throw piezoshift::core::InputError(std::string("zernike_fit: ") + e.what());
        }
      },
      py::arg("surface"), py::arg("mask") = py::none(), py::arg("terms") = 37,
      "Noll Zernike coefficients (RMS of each term) over the mask's unit disk");
}

}  // namespace piezoshift::python
