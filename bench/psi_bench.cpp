// PSI analysis of a 1024 x 1024, 13-frame set (frame13: weighted sum, unwrapping, piston and
// tilt removal, PV/RMS/PVr and a 37-term Zernike fit): the figure in docs/psi.md (< 1 s on one
// core is the target). Frames are made once, outside the timed loop.
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "piezoshift/psi/analysis.hpp"

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

}  // namespace
