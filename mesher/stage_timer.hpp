// Wall-clock and CPU time per pipeline stage, one timer for the surface and the volume pipelines.
#pragma once

#include <sys/resource.h>

#include <chrono>
#include <ctime>
#include <string>

namespace hexfem {

struct StageTime {
  std::string name;
  double seconds = 0;      // wall clock
  double cpu_seconds = 0;  // CPU time of all threads (and of finished child processes: TetGen)
};

class StageTimer {
 public:
  StageTimer()
      : start_(Clock::now()), last_(start_), cpu_start_(cpu_now()), cpu_last_(cpu_start_) {}
  // The time since the previous lap (or the start), named.
  StageTime lap(std::string name) {
    const auto now = Clock::now();
    const double cpu = cpu_now();
    StageTime t{std::move(name), std::chrono::duration<double>(now - last_).count(),
                cpu - cpu_last_};
    last_ = now;
    cpu_last_ = cpu;
    return t;
  }
  double total_seconds() const {
    return std::chrono::duration<double>(Clock::now() - start_).count();
  }
  double total_cpu_seconds() const { return cpu_now() - cpu_start_; }

 private:
  using Clock = std::chrono::steady_clock;
  static double cpu_now() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    rusage ru{};
    getrusage(RUSAGE_CHILDREN, &ru);
    return ts.tv_sec + 1e-9 * ts.tv_nsec + ru.ru_utime.tv_sec + 1e-6 * ru.ru_utime.tv_usec +
           ru.ru_stime.tv_sec + 1e-6 * ru.ru_stime.tv_usec;
  }
  Clock::time_point start_, last_;
  double cpu_start_, cpu_last_;
};

}  // namespace hexfem
