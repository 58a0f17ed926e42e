#pragma once
// Runs independent jobs (the samples of a tolerance study) on local threads, each job once, and
// reports progress on stderr: done/total, the rate and the time left. The results do not depend
// on the number of threads: each job's result depends on its index alone.
#include <cstddef>
#include <functional>
#include <string>

namespace piezoshift::app {

//! Calls job(i) for i in [0, count) on `jobs` threads (0: every core), then rethrows the first
//! exception a job threw (the others finish first). `what` names the work in the progress lines.
void run_pool(std::size_t count, unsigned jobs, const std::function<void(std::size_t)>& job,
              const std::string& what);

}  // namespace piezoshift::app
