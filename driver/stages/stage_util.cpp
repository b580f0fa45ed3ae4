// Helpers shared by the stage files.
#include "stages/stage_util.h"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <exception>
#include <stdexcept>
#include <thread>

namespace mill {

nlohmann::json case_keys(const config::Document& doc, const std::vector<std::string>& prefixes) {
  nlohmann::json all = doc.to_json(), out = nlohmann::json::object();
  for (auto it = all.begin(); it != all.end(); ++it)
    for (const auto& p : prefixes)
      if (it.key().compare(0, p.size(), p) == 0) out[it.key()] = it.value();
  return out;
}

std::string rpm_label(double rpm) { return fmt::format("rpm{:g}", rpm); }

std::filesystem::path transport_dir(const std::filesystem::path& run_dir, double rpm,
                                    std::optional<std::size_t> feed_class) {
  const std::filesystem::path t = run_dir / "transport";
  return feed_class ? t / fmt::format("class_{}", *feed_class) / rpm_label(rpm)
                    : t / rpm_label(rpm);
}

std::string impact_label(double velocity, double angle, int repeat) {
  return fmt::format("v{:g}_a{:g}_r{}", velocity, angle, repeat);
}

// <workdir>/ledger.csv, or an error naming it and the run's log.
post::EnergyLedger read_run_ledger(const std::filesystem::path& workdir) {
  const std::filesystem::path file = workdir / "ledger.csv";
  if (!std::filesystem::exists(file))
    throw std::runtime_error(fmt::format(
        "{}: missing: the deck wrote no energy ledger (expected `fix energy/ledger ... file "
        "ledger.csv`, docs/styles/fix_energy_ledger.md); log: {}",
        file.string(), (workdir / "liggghts.log").string()));
  return post::ReadEnergyLedger(file.string());
}

void run_concurrently(const std::vector<std::function<void()>>& tasks, int lanes) {
  const std::size_t n = tasks.size();
  const std::size_t threads = std::min<std::size_t>(n, static_cast<std::size_t>(std::max(1, lanes)));
  if (threads <= 1) {
    for (const auto& t : tasks) t();
    return;
  }
  std::vector<std::exception_ptr> errors(n);
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  auto worker = [&] {
    for (std::size_t i = next++; i < n && !failed.load(); i = next++) {
      try {
        tasks[i]();
      } catch (...) {
        errors[i] = std::current_exception();
        failed.store(true);
      }
    }
  };
  std::vector<std::thread> pool;
  for (std::size_t t = 0; t < threads; ++t) pool.emplace_back(worker);
  for (auto& t : pool) t.join();
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);
}

}  // namespace mill
