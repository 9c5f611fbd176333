// Where EEG comes from. Sources are polled: poll() returns at once with the whole blocks their
// clock allows (at most `max_blocks`), never waiting for data.
#pragma once

#include <set>
#include <string>
#include <vector>

#include "arbci/bci/signal.h"

namespace arbci::bci {

class EegSource {
 public:
  virtual ~EegSource() = default;
  virtual const SignalInfo& info() const = 0;
  virtual std::vector<Block> poll(int max_blocks = 64) = 0;
  // True once a finite source (a file) has delivered its last block.
  virtual bool finished() const { return false; }
  // The stimuli presented, as they happen (the simulated subject responds to those it attends).
  virtual void present(const StimulusEvent&) {}
  // Which stimulus codes the subject attends from now on (empty: none). A row/column paradigm
  // attends the target's row and its column.
  virtual void attend(const std::set<int>&) {}
  // A selection's feedback first shown at `sample`: the stimulus codes it shows as chosen (an
  // object's, or a cell's row and column). The simulated subject answers with an error-related
  // potential, large when they are not the codes it attends.
  virtual void feedback(std::int64_t /*sample*/, const std::set<int>& /*codes*/) {}
  // What the screen showed from host instant `host_s` on: the photodiode patch lit or dark. A
  // simulated amplifier puts it on its virtual photodiode channel; a real one has a real diode.
  virtual void displayed(double /*host_s*/, bool /*patch_lit*/) {}
  // The delivery delay the source itself knows of (a simulated transport), in seconds.
  virtual double knownLatencyS() const { return 0.0; }
  // Why a live source delivers nothing now (its stream lost, ...), for the panel and the log;
  // empty while it is well.
  virtual std::string fault() const { return {}; }
  // Where the signal comes from, in a line for the Session panel (empty: nothing to add).
  virtual std::string describe() const { return {}; }
  // The electrodes' impedances as the source reports them, one line ("Fz 4.2, Cz 12"); empty
  // when it reports none.
  virtual std::string impedance() const { return {}; }
  // Stimuli the source itself carries (a replayed file's events) up to the samples delivered so
  // far; each is returned once.
  virtual std::vector<StimulusEvent> takeRecordedStimuli() { return {}; }
  // Events the amplifier itself marks (a trigger box's or a photodiode's markers, sent with its
  // data) on the samples delivered so far, as annotations; each is returned once.
  virtual std::vector<Annotation> takeAnnotations() { return {}; }
};

}  // namespace arbci::bci
