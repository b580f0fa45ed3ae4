// The orchestrate command line (CLI11): options, help with examples, and the
// mapping of errors to exit statuses. cli_main is main() minus the process.
#pragma once

#include <ostream>

namespace mill {

// Parse argv and run; returns the process exit status.
int cli_main(int argc, char** argv, std::ostream& out, std::ostream& err);

// Folder of bundled cases, templates and the OpenFOAM case template.
std::string project_dir();

}  // namespace mill
