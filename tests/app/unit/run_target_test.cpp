// What the start screen says of a run's labels: without a BIDS root, a named subject's run is the
// next free among the session folders beside this one; with one, the run the dataset will give it;
// what stops a start (no subject for a BIDS export, a label BIDS refuses).
#include <gtest/gtest.h>

#include <fstream>

#include "support/test_files.h"
#include "workstation/session_requests.h"

namespace arbci::app {
namespace {

core::RunLabels labels(const std::string& subject, const std::string& session) {
  core::RunLabels l;
  l.subject = subject;
  l.session = session;
  return l;
}

void pastRun(const std::filesystem::path& folder, const std::string& subject,
             const std::string& run) {
  std::filesystem::create_directories(folder);
  std::ofstream(folder / "summary.json")
      << nlohmann::json{{"labels",
                         {{"subject", subject}, {"session", ""}, {"task", "arbci"}, {"run", run}}}}
             .dump();
}

TEST(RunTarget, WithoutABidsRootRunsAreNumberedAmongTheSessionFolders) {
  const auto study = test::freshTempPath("run_target", "folders");
  pastRun(study / "monday", "07", "1");
  pastRun(study / "tuesday", "07", "2");
  pastRun(study / "other", "08", "5");
  const ui::RunTarget target = describeRun(labels("07", ""), study / "today", {});
  EXPECT_EQ(target.problem, "");
  EXPECT_EQ(target.target.rfind("run 3 (the next free among the session folders", 0), 0u)
      << target.target;
  // Unnamed, the run is only recorded where it is.
  EXPECT_EQ(describeRun(labels("", ""), study / "today", {}).target.rfind("recorded in", 0), 0u);
}

TEST(RunTarget, WithABidsRootTheSubjectIsNeededAndTheRunIsTheDatasetsNext) {
  const auto root = test::freshTempPath("run_target", "bids");
  const ui::RunTarget unnamed = describeRun(labels("", ""), root / "out", root);
  EXPECT_NE(unnamed.problem.find("give the subject"), std::string::npos) << unnamed.problem;
  const ui::RunTarget named = describeRun(labels("07", "01"), root / "out", root);
  EXPECT_EQ(named.problem, "");
  EXPECT_NE(named.target.find("sub-07"), std::string::npos) << named.target;
  EXPECT_NE(named.target.find("run 1 (the next free)"), std::string::npos) << named.target;
  const ui::RunTarget bad = describeRun(labels("0 7", ""), root / "out", root);
  EXPECT_FALSE(bad.problem.empty());
}

}  // namespace
}  // namespace arbci::app
