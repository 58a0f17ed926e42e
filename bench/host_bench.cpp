// The costliest GCS answers (issue 27): what one line can cost the server's thread, so the other
// clients' wait (docs/safety.md, "Limits on input and on clients") is a measured bound.
#include <benchmark/benchmark.h>

#include <cmath>
#include <string>
#include <vector>

#include "piezoshift/host/data_recorder.hpp"

namespace {

using piezoshift::host::DataRecorder;
using piezoshift::host::RecorderInput;

// A DRR? of every point of every table: DataRecorder::kMaxAnswerBytes at most, 65 536 values of
// nine significant digits (the answer's size is in the counter).
void BM_DrrLargestAnswer(benchmark::State& state) {
  DataRecorder recorder;
  const char* sources[] = {"Z", "U", "V"};
  for (int t = 1; t <= DataRecorder::kTables; ++t)
    recorder.configure(t, sources[(t - 1) % 3], t <= 3 ? 2 : (t <= 6 ? 3 : 1));
  RecorderInput in{};
  for (std::size_t k = 0; k < DataRecorder::kPoints; ++k) {
    const double x = -1.234567 + 1e-3 * std::sin(0.001 * static_cast<double>(k));
    in.target = {x, 2 * x, 3 * x};
    in.position = {x + 1e-7, 2 * x - 1e-7, 3 * x};
    recorder.record(in);
  }
  std::string answer;
  for (auto _ : state) {
    recorder.read(1, -1, {}, 1e-3, answer);
    benchmark::DoNotOptimize(answer.data());
  }
  state.counters["answer_bytes"] = static_cast<double>(answer.size());
}
BENCHMARK(BM_DrrLargestAnswer)->Unit(benchmark::kMillisecond);

}  // namespace
