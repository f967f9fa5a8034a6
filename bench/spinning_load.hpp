// Background load for the benchmarks that must be measured "while another process loads the
// cores": `count` child processes, each spinning on one core for as long as the object lives
// (killed and reaped in the destructor). Linux/POSIX only; not for real-time code.
#pragma once

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <vector>

namespace pliant::bench {

class SpinningProcesses {
 public:
  explicit SpinningProcesses(int count) {
    for (int i = 0; i < count; ++i) {
      const pid_t pid = fork();
      if (pid == 0) {
        volatile unsigned long spin = 0;
        for (;;) spin = spin + 1;
      }
      if (pid > 0) pids_.push_back(pid);
    }
  }
  ~SpinningProcesses() {
    for (pid_t pid : pids_) kill(pid, SIGKILL);
    for (pid_t pid : pids_) waitpid(pid, nullptr, 0);
  }
  SpinningProcesses(const SpinningProcesses&) = delete;
  SpinningProcesses& operator=(const SpinningProcesses&) = delete;

 private:
  std::vector<pid_t> pids_;
};

}  // namespace pliant::bench
