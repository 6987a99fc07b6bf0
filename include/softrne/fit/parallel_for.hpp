#pragma once
/// \file
/// \brief Runs independent tasks on a few threads (the closed loop's screening simulations).

#include <algorithm>
#include <atomic>
#include <exception>
#include <functional>
#include <thread>
#include <vector>

namespace softrne::fit {

/// \brief Calls `task(k, w)` for k = 0..n-1 on up to `threads` threads, w being the worker
/// (0 = the calling thread, which is one of them; a worker's tasks run one after another, so
/// per-worker state indexed by w needs no lock). Task k must write only its own outputs. The
/// first exception thrown by a task stops the handing out of further tasks and is rethrown
/// here after all threads joined. A thread that cannot be started leaves its share to the
/// others.
/// \param[in] n The number of tasks.
/// \param[in] threads The most threads to use (the calling thread included).
/// \param[in] task The task, called as task(k, w).
/// \note The first exception a task throws is rethrown here, of its own type.
inline void parallel_for_workers(int n, int threads, const std::function<void(int, int)>& task) {
  const int workers = std::max(1, std::min(threads, n));
  if (workers == 1) {
    for (int k = 0; k < n; ++k) task(k, 0);
    return;
  }
  std::atomic<int> next{0};
  std::vector<std::exception_ptr> errors(static_cast<std::size_t>(workers));
  auto work = [&](int w) {
    try {
      for (int k = next++; k < n; k = next++) task(k, w);
    } catch (...) {
      errors[static_cast<std::size_t>(w)] = std::current_exception();
      next = n;  // stop handing out tasks
    }
  };
  std::vector<std::thread> pool;
  pool.reserve(static_cast<std::size_t>(workers - 1));
  for (int w = 1; w < workers; ++w) {
    try {
      pool.emplace_back(work, w);
    } catch (...) {
      break;  // no thread to be had: the others take its share
    }
  }
  work(0);
  for (std::thread& t : pool) t.join();
  for (const std::exception_ptr& e : errors)
    if (e) std::rethrow_exception(e);
}

/// \brief Calls `task(k)` for k = 0..n-1 on up to `threads` threads (see parallel_for_workers).
/// \param[in] n The number of tasks.
/// \param[in] threads The most threads to use (the calling thread included).
/// \param[in] task The task, called as task(k).
/// \note The first exception a task throws is rethrown here, of its own type.
inline void parallel_for(int n, int threads, const std::function<void(int)>& task) {
  parallel_for_workers(n, threads, [&](int k, int) { task(k); });
}

}  // namespace softrne::fit
