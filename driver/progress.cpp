// Progress reporting for stages and jobs.
#include "progress.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace mill {

Progress::Progress(std::ostream& out, bool tty, double heartbeat_seconds)
    : out_(out), tty_(tty), heartbeat_(heartbeat_seconds) {}

std::string Progress::duration(double s) {
  if (!std::isfinite(s) || s < 0) return "?";
  const long t = std::lround(s);
  if (t < 60) return fmt::format("{}s", t);
  if (t < 3600) return fmt::format("{}m {:02}s", t / 60, t % 60);
  return fmt::format("{}h {:02}m", t / 3600, (t % 3600) / 60);
}

void Progress::clear_line() {
  if (tty_ && line_open_) {
    out_ << "\r\033[K";
    line_open_ = false;
  }
}

double Progress::eta_seconds(const std::vector<RunningJob>& running, int queued, int finished,
                             double finished_seconds, int slots) {
  double sum_projected = 0, longest = 0, total_projected = 0;
  int n_projected = 0;
  for (const auto& r : running)
    if (r.fraction >= 0.02) {
      const double left = r.seconds * (1.0 - std::min(r.fraction, 1.0)) / r.fraction;
      sum_projected += left;
      longest = std::max(longest, left);
      total_projected += r.seconds / r.fraction;
      ++n_projected;
    }
  double mean_job = -1;
  if (finished > 0)
    mean_job = finished_seconds / finished;
  else if (n_projected > 0)
    mean_job = total_projected / n_projected;
  const int unknown = queued + static_cast<int>(running.size()) - n_projected;
  if (unknown > 0 && mean_job < 0) return -1;
  const double work = sum_projected + (unknown > 0 ? unknown * mean_job : 0.0);
  if (unknown == 0 && n_projected == 0) return -1;
  return std::max(longest, work / std::max(1, slots));
}

std::string Progress::status_text() const {
  std::string s = fmt::format("[{}] {}/{} jobs done", stage_, done_ + skipped_, total_);
  if (failed_) s += fmt::format(", {} failed", failed_);
  const auto now = std::chrono::steady_clock::now();
  std::vector<RunningJob> running;
  for (const auto& [label, st] : running_) {
    const auto t0 = started_.find(label);
    const double t =
        t0 == started_.end() ? 0.0 : std::chrono::duration<double>(now - t0->second).count();
    running.push_back({t, st.second});
  }
  const int left = total_ - done_ - skipped_ - failed_;
  const int queued = std::max(0, left - static_cast<int>(running.size()));
  if (left > 0) {
    const double eta = eta_seconds(running, queued, done_, job_seconds_,
                                   std::max<int>(1, static_cast<int>(running.size())));
    if (eta >= 0) s += ", ETA " + duration(eta);
  }
  for (const auto& [label, st] : running_) {
    s += " | " + label;
    if (!st.first.empty()) s += " " + st.first;
  }
  return s;
}

void Progress::draw(bool force) {
  const auto now = std::chrono::steady_clock::now();
  if (tty_) {
    if (!force && now - last_draw_ < std::chrono::milliseconds(200)) return;
    out_ << "\r\033[K" << status_text() << std::flush;
    line_open_ = true;
  } else {
    if (!force && std::chrono::duration<double>(now - last_draw_).count() < heartbeat_) return;
    out_ << status_text() << "\n" << std::flush;
  }
  last_draw_ = now;
}

void Progress::stage_begin(const std::string& stage, int total, int already_done) {
  std::lock_guard<std::mutex> g(mu_);
  clear_line();
  stage_ = stage;
  total_ = total;
  skipped_ = already_done;
  done_ = failed_ = 0;
  job_seconds_ = 0;
  running_.clear();
  stage_t0_ = std::chrono::steady_clock::now();
  out_ << fmt::format("== stage {}: {} job{}, {} already done\n", stage, total,
                      total == 1 ? "" : "s", already_done)
       << std::flush;
  last_draw_ = {};
}

void Progress::job_begin(const std::string& label) {
  std::lock_guard<std::mutex> g(mu_);
  running_[label] = {"", -1};
  started_[label] = std::chrono::steady_clock::now();
  clear_line();
  if (!tty_) out_ << fmt::format("[{}] start {}\n", stage_, label) << std::flush;
  draw(true);
}

void Progress::job_step(const std::string& label, const std::string& what, double fraction) {
  std::lock_guard<std::mutex> g(mu_);
  running_[label] = {what, fraction};
  // A job stepped without job_begin starts its clock here: counted from
  // zero seconds it would project an ETA of 0 s.
  started_.emplace(label, std::chrono::steady_clock::now());
  draw(false);
}

void Progress::job_end(const std::string& label, bool ok, double seconds) {
  std::lock_guard<std::mutex> g(mu_);
  running_.erase(label);
  started_.erase(label);
  if (ok) {
    ++done_;
    job_seconds_ += seconds;
  } else {
    ++failed_;
  }
  clear_line();
  out_ << fmt::format("[{}] {} {} in {} ({}/{})\n", stage_, ok ? "done" : "FAILED", label,
                      duration(seconds), done_ + skipped_, total_)
       << std::flush;
  draw(true);
}

void Progress::stage_end() {
  std::lock_guard<std::mutex> g(mu_);
  clear_line();
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - stage_t0_).count();
  out_ << fmt::format("== stage {} finished: {} run, {} skipped (done before), {} failed, {}\n",
                      stage_, done_, skipped_, failed_, duration(elapsed))
       << std::flush;
}

void Progress::info(const std::string& line) {
  std::lock_guard<std::mutex> g(mu_);
  clear_line();
  out_ << line << "\n" << std::flush;
}

void Progress::warn(const std::string& line) {
  std::lock_guard<std::mutex> g(mu_);
  clear_line();
  out_ << "warning: " << line << "\n" << std::flush;
}

}  // namespace mill
