// Progress of a stage: jobs done/total, the running job and its step, ETA.
// On a terminal a status line is redrawn in place; elsewhere (CI, batch jobs)
// plain lines only, at events and at most every `heartbeat` seconds.
#pragma once

#include <chrono>
#include <map>
#include <mutex>
#include <ostream>
#include <string>

namespace mill {

class Progress {
 public:
  Progress(std::ostream& out, bool tty, double heartbeat_seconds = 30.0);

  void stage_begin(const std::string& stage, int total, int already_done);
  void job_begin(const std::string& label);
  // Within a job: e.g. what = "step 1200/30000", fraction = 0.04 (or < 0 if unknown).
  void job_step(const std::string& label, const std::string& what, double fraction);
  void job_end(const std::string& label, bool ok, double seconds);
  void stage_end();
  void info(const std::string& line);
  void warn(const std::string& line);

  // "1m 05s", "3h 02m": a compact duration.
  static std::string duration(double seconds);

 private:
  void draw(bool force);
  std::string status_text() const;
  void clear_line();

  std::ostream& out_;
  bool tty_;
  double heartbeat_;
  std::mutex mu_;
  std::string stage_;
  int total_ = 0, done_ = 0, skipped_ = 0, failed_ = 0;
  double job_seconds_ = 0;  // summed wall time of jobs finished in this run
  std::map<std::string, std::pair<std::string, double>> running_;  // label -> (step text, fraction)
  std::map<std::string, std::chrono::steady_clock::time_point> started_;
  std::chrono::steady_clock::time_point stage_t0_, last_draw_;
  bool line_open_ = false;
};

}  // namespace mill
