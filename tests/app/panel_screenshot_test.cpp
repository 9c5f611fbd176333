// `arbci screenshot --panel NAME` takes its names from the panels' registry: one that is not
// there is refused, naming the option. Each panel's contents are tested in process on hand-built
// records (tests/ui/panels_test.cpp), the HMD's frame by its render stage (tests/app/unit), and the
// whole window on a live session by
// Cli.HeadlessScreenshotWritesAPngOfTheRequestedSizeWithItsStatusBar.
#include <gtest/gtest.h>

#include "support/run_process.h"

namespace arbci::test {
namespace {

TEST(PanelScreenshotErrors, AnUnknownPanelIsRefused) {
  const ProcessResult r = runProcess(
      ARBCI_EXECUTABLE, {"screenshot", "--headless", "--panel", "mixer", "--out", "/tmp/x.png"});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("--panel"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace arbci::test
