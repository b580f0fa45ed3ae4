// The stage list, in pipeline order.
#include "stages/breakage_stage.h"
#include "stages/calibrate_stage.h"
#include "stages/flow_stage.h"
#include "stages/report_stage.h"
#include "stages/sample_stage.h"
#include "stages/transport_stage.h"

namespace mill {

std::vector<std::unique_ptr<Stage>> make_stages() {
  std::vector<std::unique_ptr<Stage>> s;
  s.push_back(std::make_unique<FlowStage>());
  s.push_back(std::make_unique<SampleStage>());
  s.push_back(std::make_unique<TransportStage>());
  s.push_back(std::make_unique<CalibrateStage>());
  s.push_back(std::make_unique<BreakageStage>());
  s.push_back(std::make_unique<ReportStage>());
  return s;
}

const std::vector<std::string>& stage_names() {
  static const std::vector<std::string> n = {"flow", "sample", "transport", "calibrate", "breakage", "report"};
  return n;
}

}  // namespace mill
