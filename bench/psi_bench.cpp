// PSI analysis of a 1024 x 1024, 13-frame set (frame13: weighted sum, unwrapping, piston and
// tilt removal, PV/RMS/PVr and a 37-term Zernike fit): the figure in docs/psi.md (< 1 s on one
// core is the target). Frames are made once, outside the timed loop.
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "piezoshift/plant/random.hpp"
#include "piezoshift/psi/analysis.hpp"
#include "piezoshift/psi/fizeau_simulation.hpp"
#include "piezoshift/psi/frame_pose.hpp"

namespace {

using namespace piezoshift::psi;

struct Set {
  std::vector<Map> frames;
  Mask mask;
};

const Set& frame_set(int n, int frames, double step) {
  static Set s = [&] {
    Set out;
    out.mask = disk_mask(n, n, 0.48 * n);
    for (int k = 0; k < frames; ++k) {
      Map m(n, n);
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          const double x = 2.0 * i / n - 1.0, y = 2.0 * j / n - 1.0;
          const double phi = 12.0 * x + 8.0 * y + 20.0 * (x * x + y * y);  // ~10 fringes
          m.at(i, j) = 2000.0 + 1500.0 * std::cos(phi + k * step);
        }
      out.frames.push_back(std::move(m));
    }
    return out;
  }();
  return s;
}

void BM_PsiAnalyze1024Frame13(benchmark::State& state) {
  const Set& s = frame_set(1024, 13, std::numbers::pi / 4.0);
  AnalysisOptions o;
  o.phase.algorithm = Algorithm::kFrame13;
  for (auto _ : state) {
    Analysis a = analyze_frames(s.frames, s.mask, o);
    benchmark::DoNotOptimize(a.figures.rms);
  }
}
BENCHMARK(BM_PsiAnalyze1024Frame13)->Unit(benchmark::kMillisecond);

// One frame's pose for the fringe lock (frame_pose.hpp) on the twin's 256 px frames: the lock's
// cost per camera frame (docs/psi.md).
void BM_FramePoseFit256(benchmark::State& state) {
  const FizeauParams fizeau;
  const CameraParams camera;
  const Mask mask = disk_mask(256, 256, 120.0);
  piezoshift::plant::Rng rng(3);
  const Map surface = make_surface_nm(SurfaceSpec{}, mask, rng);
  const auto frame = [&](double piston_nm) {
    const PoseSample pose{0.0, piston_nm, 0.3, -0.2};
    return render_frame(surface, mask, fizeau, camera, std::span(&pose, 1), rng);
  };
  std::vector<Map> set;
  for (int k = 0; k < 5; ++k)
    set.push_back(frame(k * fizeau.wavelength_nm / 8.0));
  const FramePoseReference ref = frame_pose_reference(set, mask);
  const Map f = frame(20.0);
  for (auto _ : state)
    benchmark::DoNotOptimize(fit_frame_pose(f, ref, {}));
}
BENCHMARK(BM_FramePoseFit256)->Unit(benchmark::kMillisecond);

}  // namespace
