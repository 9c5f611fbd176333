// A stage's world built by hand: the services every stage gets (a clock, log.jsonl in a fresh
// folder, the operator log), and two cycle records — the one the stage writes this cycle and the
// last one — so a test can say "given this record (and these requests), the stage writes that".
#pragma once

#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "arbci/session/clock.h"
#include "arbci/session/cycle.h"
#include "arbci/session/operator_log.h"
#include "arbci/session/session_log.h"
#include "arbci/session/stage.h"
#include "support/test_files.h"

namespace arbci::test {

class StageBench {
 public:
  explicit StageBench(const std::string& name,
                      session::Clock::Mode mode = session::Clock::Mode::Stepped,
                      double display_hz = 60.0)
      : folder_(freshTempPath("stage", name)),
        clock_(mode, display_hz),
        log_((std::filesystem::create_directories(folder_), folder_ / "log.jsonl")) {
    clock_.start();
    record.time_s = clock_.frameTime(record.frame);
  }
  ~StageBench() {
    std::error_code ignored;
    std::filesystem::remove_all(folder_, ignored);
  }
  StageBench(const StageBench&) = delete;
  StageBench& operator=(const StageBench&) = delete;

  session::StageServices services() { return {clock_, log_, tell_}; }
  session::Clock& clock() { return clock_; }
  const std::filesystem::path& folder() const { return folder_; }
  const session::OperatorLog& told() const { return tell_; }

  // The record this cycle writes (fresh each next()) and the last one.
  session::CycleRecord record, previous;

  // This cycle, at frame `record.frame` (its session time: the clock's when the record was made,
  // unless a test set another).
  session::Cycle cycle() {
    record.host_s = clock_.hostOf(record.time_s);
    if (record.due_s == 0.0) record.due_s = record.time_s;
    return {record.frame,      record.time_s, record.due_s, record.host_s,
            record.eeg_sample, clock_,        record,       previous};
  }
  // Steps `stage` once on this cycle; returns its cycle (its eeg_sample as the stage set it).
  session::Cycle step(session::Stage& stage) {
    session::Cycle c = cycle();
    stage.step(c);
    record.eeg_sample = c.eeg_sample;
    return c;
  }
  // The next cycle: this record becomes the last one; a fresh record one frame on, carrying the
  // requests posted this cycle.
  void next() {
    previous = std::move(record);
    record = session::CycleRecord{};
    record.frame = previous.frame + 1;
    record.time_s = clock_.frameTime(record.frame);
    record.requests = std::move(previous.posted);
    previous.posted.clear();
  }
  // Steps `stage` for `frames` cycles, each on a fresh record (what `before` sets on it first).
  template <class Before>
  void run(session::Stage& stage, int frames, Before before) {
    for (int i = 0; i < frames; ++i) {
      before(record);
      step(stage);
      next();
    }
  }

  // log.jsonl's events named `event`, in order.
  std::vector<nlohmann::json> logged(const std::string& event) const {
    std::vector<nlohmann::json> out;
    std::ifstream in(folder_ / "log.jsonl");
    for (std::string line; std::getline(in, line);) {
      const nlohmann::json j = nlohmann::json::parse(line);
      if (j.value("event", "") == event) out.push_back(j);
    }
    return out;
  }
  // Whether the experimenter was told something containing `text`.
  bool toldOf(const std::string& text) const {
    for (const session::OperatorMessage& m : tell_.messages())
      if (m.text.find(text) != std::string::npos) return true;
    return false;
  }

 private:
  std::filesystem::path folder_;
  session::Clock clock_;
  session::SessionLog log_;
  session::OperatorLog tell_;
};

}  // namespace arbci::test
