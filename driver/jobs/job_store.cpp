// Job folders, ids and STATUS files.
#include "jobs/job_store.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <ctime>
#include <fstream>
#include <sstream>

namespace mill::jobs {
namespace fs = std::filesystem;

std::string state_name(State s) {
  switch (s) {
    case State::None: return "new";
    case State::Pending: return "pending";
    case State::Running: return "running";
    case State::Done: return "done";
    case State::Failed: return "failed";
  }
  return "?";
}

std::string job_id(const nlohmann::json& inputs) {
  // FNV-1a, 64 bit, over the canonical dump (nlohmann::json sorts object keys).
  const std::string s = inputs.dump();
  unsigned long long h = 1469598103934665603ULL;
  for (unsigned char c : s) {
    h ^= c;
    h *= 1099511628211ULL;
  }
  return fmt::format("{:016x}", h);
}

void atomic_write(const fs::path& file, const std::string& content) {
  fs::create_directories(file.parent_path());
  const fs::path tmp = file.string() + ".tmp." + std::to_string(getpid());
  int fd = open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) throw std::runtime_error(fmt::format("cannot write {}: {}", tmp.string(), strerror(errno)));
  size_t off = 0;
  while (off < content.size()) {
    ssize_t n = write(fd, content.data() + off, content.size() - off);
    if (n < 0) {
      if (errno == EINTR) continue;
      close(fd);
      throw std::runtime_error(fmt::format("cannot write {}: {}", tmp.string(), strerror(errno)));
    }
    off += static_cast<size_t>(n);
  }
  fsync(fd);
  close(fd);
  fs::rename(tmp, file);
}

void atomic_write_with(const fs::path& file, const std::function<void(std::ostream&)>& writer) {
  fs::create_directories(file.parent_path());
  const fs::path tmp = file.string() + ".tmp." + std::to_string(getpid());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error(fmt::format("cannot write {}: {}", tmp.string(), strerror(errno)));
    writer(out);
    out.flush();
    if (!out) throw std::runtime_error(fmt::format("cannot write {}: disk full?", tmp.string()));
  }
  fs::rename(tmp, file);
}

std::string utc_now() {
  std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

std::string JobStore::hostname() {
  char buf[256] = {0};
  gethostname(buf, sizeof buf - 1);
  return buf;
}

unsigned long long JobStore::process_start_ticks(long pid) {
  // Field 22 of /proc/<pid>/stat; the command name (field 2) may hold spaces.
  std::ifstream in(fmt::format("/proc/{}/stat", pid));
  std::string s;
  if (!std::getline(in, s)) return 0;
  const size_t rp = s.rfind(')');
  if (rp == std::string::npos) return 0;
  std::istringstream rest(s.substr(rp + 2));
  std::string field;
  for (int i = 3; i <= 22 && rest >> field; ++i)
    if (i == 22) return std::stoull(field);
  return 0;
}

bool JobStore::process_alive(long pid, unsigned long long start_ticks) {
  if (pid <= 0) return false;
  if (kill(static_cast<pid_t>(pid), 0) != 0 && errno != EPERM) return false;
  // Same pid, other process (pid reuse): the stored start time differs.
  return start_ticks == 0 || process_start_ticks(pid) == start_ticks;
}

JobStore::JobStore(fs::path stage_dir) : stage_dir_(std::move(stage_dir)) {}

JobStore JobStore::single(fs::path job_dir) {
  JobStore s(std::move(job_dir));
  s.single_ = true;
  return s;
}

fs::path JobStore::job_dir(const std::string& label) const {
  return single_ ? stage_dir_ : stage_dir_ / "jobs" / label;
}

Status JobStore::read_status(const std::string& label) const {
  Status s;
  std::ifstream in(job_dir(label) / "STATUS");
  if (!in) return s;
  std::string first;
  std::getline(in, first);
  if (first == "pending") s.state = State::Pending;
  else if (first == "running") s.state = State::Running;
  else if (first == "done") s.state = State::Done;
  else if (first == "failed") s.state = State::Failed;
  else s.state = State::Failed, s.reason = "unreadable STATUS";
  std::string line;
  while (std::getline(in, line)) {
    const size_t eq = line.find('=');
    if (eq == std::string::npos) continue;
    const std::string k = line.substr(0, eq), v = line.substr(eq + 1);
    try {
      if (k == "id") s.id = v;
      else if (k == "pid") s.pid = std::stol(v);
      else if (k == "host") s.host = v;
      else if (k == "start_ticks") s.start_ticks = std::stoull(v);
      else if (k == "reason") s.reason = v;
      else if (k == "time") s.time = v;
      else if (k == "scheduler_job") s.scheduler_job = v;
      else if (k == "log") s.log = v;
    } catch (const std::exception&) {
      // A damaged STATUS never reads as done: the job is run again.
      s.state = State::Failed;
      s.reason = fmt::format("unreadable STATUS ({}={})", k, v);
    }
  }
  return s;
}

void JobStore::write_status(const std::string& label, const Status& s) const {
  std::string text = state_name(s.state) + "\n";
  text += "id=" + s.id + "\n";
  if (s.state == State::Running)
    text += fmt::format("pid={}\nhost={}\nstart_ticks={}\n", s.pid, s.host, s.start_ticks);
  // One line each: a newline in a value would start a new key.
  auto line = [&](const char* key, std::string v) {
    if (v.empty()) return;
    for (auto& c : v)
      if (c == '\n' || c == '\r') c = ' ';
    text += std::string(key) + "=" + v + "\n";
  };
  line("reason", s.reason);
  line("scheduler_job", s.scheduler_job);
  line("log", s.log);
  text += "time=" + utc_now() + "\n";
  atomic_write(job_dir(label) / "STATUS", text);
}

Verdict JobStore::decide(const std::string& label, const nlohmann::json& inputs, bool force) const {
  const std::string id = job_id(inputs);
  const Status s = read_status(label);
  if (s.state == State::None) return {Decision::Run, "new"};
  if (s.state == State::Running) {
    if (s.host == hostname() && process_alive(s.pid, s.start_ticks))
      return {Decision::Busy, fmt::format("running now (pid {} on {})", s.pid, s.host)};
    if (s.host != hostname() && !force)
      return {Decision::Busy, fmt::format("marked running by pid {} on host {}; use --force if that run is dead", s.pid,
                                          s.host)};
    return {Decision::Run, fmt::format("stale: was running as pid {} on {}, which is gone", s.pid, s.host)};
  }
  if (s.id != id) return {Decision::Run, "inputs changed"};
  if (force) return {Decision::Run, "forced"};
  if (s.state == State::Done) return {Decision::Skip, "done"};
  if (s.state == State::Failed) return {Decision::Run, "failed before: " + s.reason};
  return {Decision::Run, "pending"};
}

void JobStore::mark_running(const std::string& label, const nlohmann::json& inputs, const std::string& scheduler_job,
                            const std::string& log) const {
  fs::create_directories(job_dir(label));
  nlohmann::json j = {{"label", label}, {"id", job_id(inputs)}, {"inputs", inputs}};
  atomic_write(job_dir(label) / "job.json", j.dump(2) + "\n");
  Status s;
  s.state = State::Running;
  s.id = job_id(inputs);
  s.pid = getpid();
  s.host = hostname();
  s.start_ticks = process_start_ticks(s.pid);
  s.scheduler_job = scheduler_job;
  s.log = log;
  write_status(label, s);
}

void JobStore::mark_done(const std::string& label) const {
  Status s = read_status(label);
  s.state = State::Done;
  s.reason.clear();
  write_status(label, s);
}

void JobStore::mark_failed(const std::string& label, const std::string& reason) const {
  Status s = read_status(label);
  s.state = State::Failed;
  s.reason = reason;
  write_status(label, s);
}

}  // namespace mill::jobs
