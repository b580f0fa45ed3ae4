// Progress of a stage: jobs done/total, the running job and its step, ETA.
// On a terminal a status line is redrawn in place; elsewhere (CI, batch jobs)
// plain lines only, at events and at most every `heartbeat` seconds.
#pragma once

#include <chrono>
#include <map>
#include <mutex>
#include <ostream>
#include <string>
#include <vector>

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

  // A running job: seconds since it started and the fraction it reported
  // (< 0 if none yet).
  struct RunningJob {
    double seconds = 0;
    double fraction = -1;
  };
  // Seconds until the stage is done, or < 0 when there is nothing to go on.
  // Each running job that reported a fraction f after t seconds needs
  // t (1 - f) / f more (jobs of one stage may differ a hundredfold, e.g. an
  // in-mill lump beside single impacts); a running job without a fraction
  // and each queued job count as the mean finished job (or as the mean
  // projected running job when none has finished). Jobs run `slots` at a
  // time: the stage ends no earlier than its longest running job.
  static double eta_seconds(const std::vector<RunningJob>& running, int queued, int finished,
                            double finished_seconds, int slots);

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
