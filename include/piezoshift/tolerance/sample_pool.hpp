#pragma once
// Runs independent jobs (the samples of a tolerance study) on local threads, each job once. The
// results do not depend on the number of threads: each job's result depends on its index alone.
#include <cstddef>
#include <functional>
#include <string>

namespace piezoshift::tolerance {

//! Called after each job, one call at a time: jobs done, their total, seconds since the start.
using PoolProgress = std::function<void(std::size_t done, std::size_t total, double elapsed_s)>;

//! Calls job(i) for i in [0, count) on `jobs` threads (0: every core), then rethrows the first
//! exception a job threw (the others finish first).
void run_pool(std::size_t count, unsigned jobs, const std::function<void(std::size_t)>& job,
              const PoolProgress& progress = {});

//! A PoolProgress printing "piezoshift: <what>: 3/16 done, 2.10/s, 6 s left" on stderr, at most
//! one line a second (and the last), so a log stays readable.
PoolProgress progress_lines(std::string what);

}  // namespace piezoshift::tolerance
