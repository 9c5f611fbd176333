// Whether to trust a run's data, from hand-built summaries: the calibration's AUC beside chance
// and the simulated subject's, each reason for caution marked (an AUC under the subject's range, a
// review gone online anyway, flashes off limits, bad channels accepted, an EEG fault, an
// interruption), a clean run with none, and the notes listed.
#include "arbci/session/trust_report.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

namespace arbci::session {
namespace {

nlohmann::json clean() {
  return nlohmann::json{
      {"ended", "finished"},
      {"calibration",
       {{"auc", 0.86},
        {"auc_95", {0.80, 0.92}},
        {"flashes", {{"targets", 64}, {"others", 192}}},
        {"selections", 8},
        {"reviews",
         nlohmann::json::array({{{"decision", "go online"}, {"auc", 0.86}, {"at_s", 74}}})}}},
      {"objects", {{"right", 3}, {"of", 3}}},
      {"cells", {{"right", 3}, {"of", 3}}},
      {"timing_gate",
       {{"verdict", "within limits"}, {"long_flashes", 0}, {"short_gaps", 0}, {"short_soas", 0}}},
      {"signal_quality", {{"verdict", "passed"}, {"bad_channels", 0}}},
      {"timing", {{"lost_samples", 0}, {"soa_ms", {{"median", 183.6}, {"configured", 180}}}}},
      {"eeg", {{"faults", nlohmann::json::array()}}},
      {"trials", nlohmann::json::array()},
      {"notes", nlohmann::json::array({{{"t", 30.5}, {"text", "the subject blinked a lot"}}})}};
}

int cautions(const std::vector<TrustRow>& rows) {
  int n = 0;
  for (const TrustRow& r : rows) n += r.caution;
  return n;
}

const TrustRow* row(const std::vector<TrustRow>& rows, const std::string& what) {
  for (const TrustRow& r : rows)
    if (r.what == what) return &r;
  return nullptr;
}

TEST(TrustReport, ACleanRunHasNoCautionAndItsAucIsPutBesideChanceAndTheSubject) {
  const auto rows = trustRows(clean());
  EXPECT_EQ(cautions(rows), 0);
  const TrustRow* calibration = row(rows, "calibration");
  ASSERT_NE(calibration, nullptr);
  EXPECT_NE(calibration->text.find("cross-validated AUC 0.860 (95 % 0.800-0.920)"),
            std::string::npos)
      << calibration->text;
  EXPECT_NE(calibration->text.find("chance with these 64 target and 192 other flashes: 0.50 +/-"),
            std::string::npos)
      << calibration->text;
  EXPECT_NE(calibration->text.find("the simulated default subject reaches 0.78"),
            std::string::npos);
  ASSERT_NE(row(rows, "note at 30.5 s"), nullptr);
  EXPECT_EQ(row(rows, "note at 30.5 s")->text, "the subject blinked a lot");
  ASSERT_NE(row(rows, "online objects"), nullptr);
  EXPECT_NE(row(rows, "online objects")->text.find("3 of 3 right"), std::string::npos);
}

TEST(TrustReport, EachReasonForCautionIsMarked) {
  nlohmann::json s = clean();
  s["calibration"]["auc"] = 0.61;
  s["calibration"]["reviews"][0]["decision"] = "go online anyway";
  s["timing_gate"] = {{"verdict", "off limits (see the recording's Timing notes)"},
                      {"long_flashes", 144},
                      {"short_gaps", 2},
                      {"short_soas", 1},
                      {"pauses", 1},
                      {"policy", "pause"},
                      {"policy_at_end", "annotate"}};
  s["signal_quality"] = {
      {"verdict", "accepted by the experimenter"},
      {"bad_channels", 1},
      {"channels", {{{"channel", "Oz"}, {"grade", "bad"}, {"finding", "flat: SD 0.1 uV"}}}}};
  s["eeg"]["faults"] = {{{"t", 45.0}, {"fault", "the EEG source ended"}}};
  s["trigger"] = {
      {"device", "/dev/ttyUSB0"}, {"written", 122}, {"failed", 35}, {"latency_max_ms", 0.23}};
  s["trials"] = {
      {{"trial", 2},
       {"interruptions", {{{"kind", "emergency stop"}, {"at_s", 80.2}, {"resumed_s", 89.0}}}}}};
  const auto rows = trustRows(s);
  for (const char* what :
       {"calibration", "review", "timing", "triggers", "EEG channels", "EEG stream", "trial 2"}) {
    ASSERT_NE(row(rows, what), nullptr) << what;
    EXPECT_TRUE(row(rows, what)->caution) << what;
  }
  EXPECT_NE(row(rows, "timing")->text.find("147 flashes off limits"), std::string::npos)
      << row(rows, "timing")->text;
  EXPECT_NE(row(rows, "timing")->text.find("went on annotated"), std::string::npos);
  EXPECT_NE(row(rows, "EEG channels")->text.find("Oz (flat: SD 0.1 uV)"), std::string::npos);
  EXPECT_NE(row(rows, "trial 2")->text.find("went on at 89.0 s"), std::string::npos);
  EXPECT_NE(row(rows, "triggers")->text.find("35 not sent"), std::string::npos)
      << row(rows, "triggers")->text;
}

}  // namespace
}  // namespace arbci::session
