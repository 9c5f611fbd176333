// The EEG's first stage: the source (the simulated subject, a file replayed in real time, an LSL
// stream, an eegdev amplifier) acquired on its own clock into a ring buffer; each cycle takes the
// blocks that arrived (stepped: those generated up to the cycle's time), the losses (gaps,
// overflows), and the source's fault, and stamps the cycle with its EEG sample. What the screen
// showed and what the subject attends go to the source, as they would reach a subject: a
// simulated one answers with its ERPs and its virtual photodiode. The clock model it fits lends
// the session's clock its sample map. A source that ends or goes silent is a fault on the record
// within a second: a file at its end ends the run; a live source pauses it, named with the time
// since its last sample.
#pragma once

#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "arbci/bci/acquisition.h"
#include "arbci/bci/paradigm.h"
#include "arbci/session/eeg_sources.h"
#include "arbci/session/session_config.h"
#include "arbci/session/stage.h"

namespace arbci::session {

struct EegAcquisitionSettings {
  EegSettings eeg;
  // A flash's nominal duration (the paradigm's, in whole frames; the schema's default here).
  double flash_s = bci::ParadigmSettings().flashSeconds();
  std::string session_file;   // for messages naming a key
  bool experimenter = false;  // someone at the window who can bring a silent source back
  // Before the run: the files named exist; throws SessionConfigError naming the key and value.
  void validate() const;
};

class EegAcquisitionStage final : public Stage {
 public:
  // Starts acquiring from `source` (openEegSource's). Throws SessionConfigError naming the key
  // (a photodiode channel the source lacks).
  EegAcquisitionStage(const EegAcquisitionSettings& settings, OpenedEegSource source, Clock& clock,
                      const StageServices& services);
  ~EegAcquisitionStage() override;

  const char* name() const override { return "eeg"; }
  void step(Cycle& cycle) override;
  // Live, the EEG of the last frames is still on its way: waits for it (at most 1 s), then stops.
  void stop(Cycle& cycle, const std::string& reason) override;
  void report(nlohmann::json& summary) const override;

  // Every channel the source delivers (the photodiode too): what the recording holds.
  const bci::SignalInfo& info() const { return acquisition_->info(); }
  // The EEG channels only: what filters, epochs and models see.
  const bci::SignalInfo& eegInfo() const { return eeg_info_; }

 private:
  void toSource(const Cycle& cycle);
  void take(Cycle& cycle);
  bci::Block eegOnly(const bci::Block& block) const;
  // A held-up delivery: logged, annotated in the recording with the flashes whose stamps were
  // extrapolated across it, counted for the summary.
  void noteStall(Cycle& cycle, const bci::DeliveryStall& stall);
  std::string sourceLine() const;

  EegAcquisitionSettings settings_;
  StageServices s_;
  std::unique_ptr<bci::Acquisition> acquisition_;
  bci::SignalInfo eeg_info_;
  std::shared_ptr<const bci::SignalInfo> all_info_;
  int photodiode_ = -1;              // the photodiode's channel in the source's blocks
  std::int64_t lost_logged_ = 0;     // lost samples already in the log
  std::int64_t source_markers_ = 0;  // the amplifier's own markers, recorded as annotations
  std::string fault_logged_;         // the source's fault last logged (empty: none)
  nlohmann::json faults_ = nlohmann::json::array();  // each fault as it began, for the summary
  std::int64_t next_sample_ = 0;                     // after the last block taken
  // The flashes presented lately (host time, onset sample): those a stall covered are named.
  std::deque<std::pair<double, std::int64_t>> recent_onsets_;
  struct StallTotals {
    int count = 0;
    double longest_s = 0.0;
    std::int64_t samples = 0;
    int uncertain_flashes = 0;
  } stalls_;
  bool drift_warned_ = false;
  // A source that stops: a finite one (a file) at its end ends the run; a live one silent for
  // kSilentS is a fault (the paradigm pauses) named with the time since its last sample, and
  // without an experimenter ends the run after kSilentEndS.
  void watchDelivery(Cycle& cycle, bool delivered);
  // Without an experimenter a fault that lasts kSilentEndS ends the run, saying why.
  void endIfNobodyCanHelp(Cycle& cycle);
  std::optional<double> fault_since_host_s_;
  std::optional<double> last_delivery_s_;  // session time the last samples arrived
  double last_delivery_host_s_ = 0.0;      // and host time
  std::string silence_;                    // the silence's fault while it lasts
  static constexpr double kSilentS = 1.0;
  // Long enough for an outlet restarted at once to be found again, short enough that a run
  // nobody watches ends within 3 s of its last sample.
  static constexpr double kSilentEndS = 1.5;
};

}  // namespace arbci::session
