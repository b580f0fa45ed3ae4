// Stage 'report': report/index.html and report/summary.json (issue 8).
#include "stages/report_stage.h"

namespace mill {

Plan ReportStage::plan(const StageContext&) const {
  Plan p;
  p.jobs.push_back({"report", nlohmann::json::object(), "report/index.html from every stage's outputs"});
  return p;
}

void ReportStage::run_job(StageContext&, const JobSpec&, const std::filesystem::path&) {
  throw NotImplemented("stage 'report' is not implemented yet (issue 8: report and mill product)");
}

}  // namespace mill
