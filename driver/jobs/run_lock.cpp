// The run-folder lock (flock) and the record of its holders.
#include "jobs/run_lock.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <sstream>

#include "jobs/job_store.h"

namespace mill::jobs {
namespace fs = std::filesystem;

namespace {

std::string read_all(int fd) {
  std::string text;
  char buf[4096];
  lseek(fd, 0, SEEK_SET);
  for (ssize_t n; (n = read(fd, buf, sizeof buf)) > 0;) text.append(buf, static_cast<size_t>(n));
  return text;
}

// The holders the lock file records, one per line, in words; "" if none.
std::string holders_text(const std::string& text) {
  std::istringstream in(text);
  std::string line, out;
  while (std::getline(in, line)) {
    long pid = 0;
    char host[256] = {0}, since[64] = {0};
    if (std::sscanf(line.c_str(), "pid=%ld host=%255s since=%63s", &pid, host, since) != 3)
      continue;
    if (host == JobStore::hostname() && !JobStore::process_alive(pid, 0)) continue;  // gone
    const size_t cmd = line.find(" command=");
    out += fmt::format("{}pid {} on {} since {}{}", out.empty() ? "" : "; ", pid, host, since,
                       cmd == std::string::npos ? "" : " (" + line.substr(cmd + 9) + ")");
  }
  return out;
}

void write_all(int fd, const std::string& s) {
  size_t off = 0;
  while (off < s.size()) {
    const ssize_t n = write(fd, s.data() + off, s.size() - off);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return;  // the record is informative; the flock is the lock
    off += static_cast<size_t>(n);
  }
}

}  // namespace

fs::path RunLock::file(const fs::path& run_dir, const std::string& stage) {
  return run_dir / (stage.empty() ? std::string("orchestrate.lock")
                                  : "orchestrate-" + stage + ".lock");
}

RunLock::RunLock(const fs::path& run_dir, Mode mode, const std::string& command,
                 const std::string& stage) {
  fs::create_directories(run_dir);
  const fs::path f = file(run_dir, stage);
  // O_CLOEXEC: engine children must not inherit (and so keep) the lock.
  fd_ = open(f.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0)
    throw std::runtime_error(
        fmt::format("cannot open the run-folder lock {}: {}", f.string(), strerror(errno)));
  const int op = (mode == Mode::Exclusive ? LOCK_EX : LOCK_SH) | LOCK_NB;
  while (flock(fd_, op) != 0) {
    if (errno == EINTR) continue;
    const int err = errno;
    const std::string holders = err == EWOULDBLOCK ? holders_text(read_all(fd_)) : "";
    close(fd_);
    fd_ = -1;
    if (err == ENOLCK || err == EOPNOTSUPP) {
      // A file system without locks (NFS without lockd): run, but say so.
      warning_ = fmt::format(
          "{}: the file system cannot lock the run folder ({}), so nothing keeps a second "
          "command out of it; run one orchestrate at a time on it",
          f.string(), strerror(err));
      return;
    }
    if (err != EWOULDBLOCK)
      throw std::runtime_error(
          fmt::format("cannot lock the run folder ({}): {}", f.string(), strerror(err)));
    throw RunFolderBusy(fmt::format(
        "--output {}: {}the run folder is in use by another orchestrate ({}); wait until it ends "
        "(or stop it), or use another --output; the lock is {}",
        run_dir.string(), stage.empty() ? "" : "stage " + stage + " of ",
        holders.empty() ? "holder not recorded" : holders, f.string()));
  }
  const std::string me = fmt::format("pid={} host={} since={} command={}\n", getpid(),
                                     JobStore::hostname(), utc_now(), command);
  if (mode == Mode::Exclusive) {
    if (ftruncate(fd_, 0) == 0) lseek(fd_, 0, SEEK_SET);
  } else {
    // Shared holders add a line each; lines of holders that are gone are
    // dropped by the next exclusive holder.
    lseek(fd_, 0, SEEK_END);
  }
  write_all(fd_, me);
}

RunLock::~RunLock() {
  if (fd_ >= 0) close(fd_);  // closing releases the flock
}

}  // namespace mill::jobs
