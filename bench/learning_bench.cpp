// Learning from use against a calibration run, replayed on copy-task recordings (`arbci eeg
// simulate`, or any single-stimulus recording with its targets marked): the first
// --calibration selections are the calibration run, the next --trials the trials. Calibrated: a
// model trained on the calibration run decides every trial, and the arm goes every time. Learning
// from use (paradigm.calibration none): the calibration run is not used; before trial k the model
// is the one the session would hold (bci::learnFromUse over trials 1..k-1, their labels removed),
// it decides trial k, and the arm goes only when the fit with trial k in (1..k) is trusted
// (bci::judgeTrust) and decodes trial k as it was decided, and that decision was as certain as
// paradigm.certainty, as the session does. Decisions are made as the session makes them: scores
// accumulated under the model's score model (a learnt one's separation bounded by the selections
// decided before, as scored then: bci/held_out_separation.h), dynamic stopping for the calibrated
// model and, once trusted, for the learning one, whose selections may then flash up to
// paradigm.learning_max_sequences (record that many per selection: `--sequences 16`); fits and
// decisions see only the sequences a session would have shown. Per file and in all: object
// selections right online (trials 11 on, as the issue counts them), arm sent to a wrong object,
// post-hoc accuracy of the last fit, and the time from Start to the first right placement,
// estimated from the session's default timing (TimeModel below; the robot's time is the same in
// both); beside them, the soonest any learner that waits for certainty could place, its models
// trained with the true labels (certainCeiling). The session's own classifier settings
// (SessionConfig's defaults) are used.
// Usage: learning_bench FILES... [--calibration 8] [--trials 30] [--from 11] [--trace F]
//        [--ceiling-only] [--untrusted-sequences N] [--unbounded] [--independent-flashes]
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <set>
#include <string>

#include "arbci/bci/held_out_separation.h"
#include "arbci/bci/intervals.h"
#include "arbci/bci/learning_from_use.h"
#include "arbci/bci/p300_dataset.h"
#include "arbci/bci/recording.h"
#include "arbci/bci/selection_marks.h"
#include "arbci/session/session_config.h"

using namespace arbci;

namespace {

// Seconds of the default session (paradigm defaults, 4 objects) as a headless default session
// takes them: a cued calibration selection (cue, 8 sequences of 4 flashes, pause; training
// included), a learning trial (its selection, the result shown, the pause) and a whole trial with
// the arm (both selections with dynamic stopping, results, grasp and put-down at the simulated
// arm's default speed). Measure them again from a session's log when the defaults change.
struct TimeModel {
  double calibration_selection_s = 8.9;
  double training_s = 0.0;  // within the above
  double learning_trial_s = 8.5;
  double trial_s = 29.5;
  // A held selection that the fit with it in trusted and decoded as shown goes on to the arm: a
  // whole trial whose object selection ran all its sequences and waited for that fit (the median
  // duration of such trials in headless sessions). A selection that flashes more sequences than
  // `sequences` (learning, trusted) adds their time to any of these.
  double held_then_sent_s = 30.0;
};

// An online decision, for the reliability tables: what it claimed and whether it was right.
struct Judged {
  const char* kind;  // "objects" or "cells"
  int file = 0, trial = 0;
  double certainty = 0.0;
  bool right = false;
  int sequences = 0;
};

struct Outcome {
  std::vector<Judged> decisions;
  // Per trial k (0-based): decided right online; the arm sent.
  std::vector<bool> right_at, trusted_at;
  int online_made = 0, online_right = 0;  // trials --from on
  int arm_sent = 0, arm_wrong = 0;
  int post_hoc_right = 0, post_hoc_made = 0;
  double first_right_s = -1.0;  // -1: never
  int first_trusted = 0;        // 0: never
};

struct Replay {
  int index = 0;  // the file's, for the trace
  bci::Recording recording;
  std::vector<int> number;             // each stimulus's selection (1-based)
  std::map<int, int> target;           // selection -> attended code (a cell's: its row's)
  std::map<int, std::set<int>> truth;  // selection -> attended codes
  std::vector<int> sequence;           // each stimulus's sequence within its selection (0-based)
};

// How many sequences of each selection the session would have shown (a recording may hold
// more): the rest are left out of every fit and decision.
struct Shown {
  explicit Shown(int all) : otherwise(all) {}
  int otherwise;
  std::map<int, int> of;  // selection -> sequences, where it differs
  int at(int number) const {
    const auto found = of.find(number);
    return found != of.end() ? found->second : otherwise;
  }
};

// Each stimulus's selection: where the recording marks them (a session, or `arbci eeg simulate
// --trials`), the mark it follows; else runs of flashes apart by more than four stimulus onsets
// (as buildDataset groups a copy task).
Replay replayOf(bci::Recording recording, const std::vector<std::int64_t>& starts) {
  Replay r;
  r.recording = std::move(recording);
  const double soa = bci::layoutOf(r.recording).soa_s;
  const double gap = std::max(1.0, 4.0 * soa) * r.recording.info.rate_hz;
  int selection = 0;
  std::int64_t previous = -1;
  size_t next_start = 0;
  std::map<int, int> flashed;  // of the selection: code -> times
  for (const bci::StimulusEvent& e : r.recording.stimuli) {
    bool begins = previous < 0;
    if (starts.empty()) {
      begins = begins || static_cast<double>(e.sample - previous) > gap;
    } else {
      while (next_start < starts.size() && starts[next_start] <= e.sample) {
        begins = begins || starts[next_start] > previous;
        ++next_start;
      }
    }
    if (begins) {
      ++selection;
      flashed.clear();
    }
    previous = e.sample;
    r.number.push_back(selection);
    r.sequence.push_back(flashed[e.code]++);
    if (e.target) {
      r.truth[selection].insert(e.code);
      if (!r.target.count(selection)) r.target[selection] = e.code;
    }
  }
  return r;
}

// The object selections (the calibration run's, then each trial's) and, where the recording has
// them, the trials' cell selections (numbered by trial).
struct Loaded {
  Replay objects;
  std::optional<Replay> cells;
};

Loaded load(const std::string& file) {
  bci::Recording recording = bci::readRecording(file);
  const std::vector<bci::MarkedSelection> marks = bci::markedSelections(recording);
  if (marks.empty()) return {replayOf(std::move(recording), {}), std::nullopt};
  auto starts = [](const bci::SelectionsOfKind& part) {
    std::vector<std::int64_t> out;
    for (const auto& m : part.selections) out.push_back(m.sample);
    return out;
  };
  const bci::SelectionsOfKind objects = bci::selectionsOfKind(
      recording, marks, {bci::SelectionKind::Calibration, bci::SelectionKind::Objects});
  Loaded loaded{replayOf(objects.recording, starts(objects)), std::nullopt};
  const bci::SelectionsOfKind cells =
      bci::selectionsOfKind(recording, marks, {bci::SelectionKind::Cells});
  if (!cells.selections.empty()) loaded.cells = replayOf(cells.recording, starts(cells));
  return loaded;
}

// The recording with only the stimuli of selections [first, last] the session would have shown,
// labels removed unless `keep`.
std::pair<bci::Recording, std::vector<int>> part(const Replay& r, int first, int last, bool keep,
                                                 const Shown& shown) {
  bci::Recording out = r.recording;
  out.stimuli.clear();
  std::vector<int> numbers;
  for (size_t i = 0; i < r.recording.stimuli.size(); ++i) {
    if (r.number[i] < first || r.number[i] > last) continue;
    if (r.sequence[i] >= shown.at(r.number[i])) continue;
    bci::StimulusEvent e = r.recording.stimuli[i];
    if (!keep) e.target = e.known = false;
    out.stimuli.push_back(e);
    numbers.push_back(r.number[i]);
  }
  return {out, numbers};
}

std::map<int, int> decode(const bci::P300Model& model, const Replay& r, int first, int last,
                          const bci::PipelineSettings& pipeline, const Shown& shown) {
  const auto [recording, numbers] = part(r, first, last, false, shown);
  return bci::decodeSelections(model, recording, numbers, pipeline);
}

// Selection `number` decided online by `model` as the session decides (bci::SelectionAccumulator
// with the model's score model): after each whole sequence from the rule's minimum on, it stops
// once certain enough (dynamic stopping), else after all of them.
struct Online {
  std::optional<int> code;
  std::set<int> codes;  // a cell's: its row and column
  double certainty = 0.0;
  int sequences = 0;
  bci::HeldOutSelection scored;  // its flashes as decided, standardised by the model's scores
};
// The selections of one kind decided so far (objects, or cells), each flash standardised by the
// model that scored it: the session decides the next of that kind under the model's score model
// held to the separation they show (P300Stage::scoreModelNow), once there are enough.
struct Decided {
  std::vector<bci::HeldOutSelection> selections;
  bool bounds = true;  // false: a learnt model's objects, bounded at each fit instead
  bci::ScoreModel bound(const bci::ScoreModel& model, const bci::ParadigmLayout& layout) const {
    bci::ScoreModel out = model;
    if (bounds && static_cast<int>(selections.size()) >= bci::kMinHeldOutSelections)
      bci::boundByHeldOut(out, selections, layout);
    return out;
  }
};

Online decideOnline(const bci::P300Model& model, const Replay& r, int number,
                    const bci::PipelineSettings& pipeline, const bci::StoppingRule& rule,
                    Decided* decided = nullptr) {
  const auto [recording, numbers] = part(r, number, number, false, Shown{rule.max_sequences});
  bci::DatasetOptions options;
  options.keep_unknown = true;
  const bci::P300Dataset data = bci::buildDataset({recording}, pipeline, {}, options);
  bci::SelectionAccumulator accumulator(
      data.layout, decided ? decided->bound(model.score_model, data.layout) : model.score_model);
  Online out;
  for (int e = 0; e < data.epochs(); ++e) {
    const auto i = static_cast<size_t>(e);
    const double score = model.classifier->score(data.features.row(e));
    accumulator.add(data.code[i], score);
    out.scored.code.push_back(data.code[i]);
    out.scored.z.push_back(bci::standardised(model.score_model, score));
    const bool sequence_ends = e + 1 == data.epochs() || data.sequence[i + 1] != data.sequence[i];
    if (sequence_ends && accumulator.shouldStop(rule)) break;
  }
  const bci::Decision d = accumulator.decide();
  if (!d.codes.empty() && accumulator.flashes() > 0) {
    out.code = *d.codes.begin();
    out.codes = d.codes;
  }
  out.certainty = d.certainty;
  out.sequences = accumulator.completeSequences();
  if (decided) decided->selections.push_back(out.scored);
  return out;
}

// Trial k's cell selection decided by `model` as the session decides it, into the decisions.
void decideCell(const bci::P300Model& model, const Replay& cells, int trial,
                const bci::PipelineSettings& pipeline, const bci::StoppingRule& rule,
                Decided& decided, Outcome& o) {
  if (!cells.truth.count(trial)) return;
  const Online d = decideOnline(model, cells, trial, pipeline, rule, &decided);
  o.decisions.push_back(
      {"cells", cells.index, trial, d.certainty, d.codes == cells.truth.at(trial), d.sequences});
}

// Every flash of the selections [first, last] scored by `model`, all the sequences recorded, as
// CSV rows: file, kind, selection, its flash index, sample, code, target, score.
void writeScores(std::FILE* out, const char* kind, const bci::P300Model& model, const Replay& r,
                 int first, int last, const bci::PipelineSettings& pipeline) {
  for (int number = first; number <= last; ++number) {
    const auto [recording, numbers] = part(r, number, number, true, Shown{1000});
    if (recording.stimuli.empty()) continue;
    const bci::P300Dataset data = bci::buildDataset({recording}, pipeline);
    for (int e = 0; e < data.epochs(); ++e) {
      const auto i = static_cast<size_t>(e);
      std::fprintf(out, "%d,%s,%d,%d,%lld,%d,%d,%.6f\n", r.index, kind, number, e,
                   static_cast<long long>(data.sample[i]), data.code[i],
                   static_cast<int>(data.target[i]), model.classifier->score(data.features.row(e)));
    }
  }
}

Outcome calibrated(const Replay& r, const Replay* cells, int calibration, int trials, int from,
                   const bci::PipelineSettings& pipeline, const bci::TrainingSettings& training,
                   const bci::StoppingRule& stopping, const TimeModel& time,
                   bool independent_flashes, std::FILE* scores = nullptr) {
  Outcome o;
  const auto [recording, numbers] = part(r, 1, calibration, true, Shown{stopping.max_sequences});
  const bci::P300Dataset data = bci::buildDataset({recording}, pipeline);
  const bci::TrainingResult trained = bci::trainModel(data, pipeline, training);
  bci::P300Model model = trained.model;
  // --independent-flashes: the certainty as it was before its two terms (every flash independent
  // evidence, no selection's separation held to what those decided show), for comparison.
  if (independent_flashes) model.score_model.rho = 0.0;
  if (scores) {
    // The calibration run's flashes as cross-validation scored them (what the score model is
    // fitted on), then every trial's flashes by the model.
    const auto& cv = trained.cross_validation;
    for (size_t s = 0; s < data.selections.size(); ++s) {
      int index = 0;
      for (int row : data.selections[s].epochs) {
        const auto i = static_cast<size_t>(row);
        std::fprintf(scores, "%d,cv,%zu,%d,%lld,%d,%d,%.6f\n", r.index, s + 1, index++,
                     static_cast<long long>(data.sample[i]), data.code[i],
                     static_cast<int>(data.target[i]), cv.scores[i]);
      }
    }
    std::fprintf(scores, "%d,model,%.9g,%.9g,%.9g,0,0,0\n", r.index, model.score_model.target_mean,
                 model.score_model.other_mean, model.score_model.sd);
    writeScores(scores, "objects", model, r, calibration + 1, calibration + trials, pipeline);
    if (cells) writeScores(scores, "cells", model, *cells, 1, trials, pipeline);
  }
  double t = calibration * time.calibration_selection_s + time.training_s;
  Decided decided_objects, decided_cells;
  decided_objects.bounds = decided_cells.bounds = !independent_flashes;
  for (int k = 1; k <= trials; ++k) {
    const int number = calibration + k;
    const Online d = decideOnline(model, r, number, pipeline, stopping, &decided_objects);
    const bool right = d.code && *d.code == r.target.at(number);
    o.decisions.push_back({"objects", r.index, k, d.certainty, right, d.sequences});
    if (cells) decideCell(model, *cells, k, pipeline, stopping, decided_cells, o);
    o.right_at.push_back(right);
    o.trusted_at.push_back(true);
    if (k >= from) {
      ++o.online_made;
      o.online_right += right;
    }
    ++o.arm_sent;
    o.arm_wrong += !right;
    t += time.trial_s;
    if (right && o.first_right_s < 0.0) o.first_right_s = t;
  }
  return o;
}

// The ceiling of any learning without labels: before trial k, a model trained on trials 1..k-1
// with their true labels (none before two). Per trial: decided right.
std::vector<bool> labelsKnown(const Replay& r, int calibration, int trials, const Shown& shown,
                              const bci::PipelineSettings& pipeline,
                              const bci::TrainingSettings& training) {
  std::vector<bool> right_at;
  for (int k = 1; k <= trials; ++k) {
    const int number = calibration + k;
    bool right = false;
    if (k > 2) {
      try {
        const auto [recording, numbers] = part(r, calibration + 1, number - 1, true, shown);
        const bci::P300Dataset data = bci::buildDataset({recording}, pipeline);
        const bci::P300Model model = bci::trainModel(data, pipeline, training).model;
        const auto d = decode(model, r, number, number, pipeline, shown);
        right = d.count(number) && d.at(number) == r.target.at(number);
      } catch (const std::exception&) {
        // Too little to train on.
      }
    }
    right_at.push_back(right);
  }
  return right_at;
}

// The soonest any learner that waits for certainty can place an object right: before trial k, a
// model trained on trials 1..k-1 with their true labels (as shown: `sequences` each) decides trial
// k with dynamic stopping up to `extended` sequences; the first decision both right and as certain
// as the rule asks is placed, on that trial, the trials before counted as learning trials (none of
// them extended). The learner without labels can only be later: its models are at best these.
// Seconds from Start, -1: never.
double certainCeiling(const Replay& r, int calibration, int trials,
                      const bci::PipelineSettings& pipeline, const bci::TrainingSettings& training,
                      const bci::StoppingRule& stopping, int extended, const TimeModel& time) {
  const bci::ParadigmLayout layout = bci::layoutOf(r.recording);
  bci::StoppingRule rule = stopping;
  rule.max_sequences = extended;
  for (int k = 3; k <= trials; ++k) {
    const int number = calibration + k;
    try {
      const auto [recording, numbers] =
          part(r, calibration + 1, number - 1, true, Shown{stopping.max_sequences});
      const bci::P300Dataset data = bci::buildDataset({recording}, pipeline);
      const bci::P300Model model = bci::trainModel(data, pipeline, training).model;
      const Online d = decideOnline(model, r, number, pipeline, rule);
      if (d.code && *d.code == r.target.at(number) && d.certainty >= stopping.certainty) {
        const double extra_s =
            std::max(0, d.sequences - stopping.max_sequences) * layout.stimuli * layout.soa_s;
        return (k - 1) * time.learning_trial_s + time.trial_s + extra_s;
      }
    } catch (const std::exception&) {
      // Too little to train on.
    }
  }
  return -1.0;
}

Outcome learnt(const Replay& r, const Replay* cells, int calibration, int trials, int from,
               const bci::PipelineSettings& pipeline, const bci::TrainingSettings& training,
               const bci::TrustRule& rule, const bci::StoppingRule& stopping,
               int extended_sequences, int untrusted_sequences, bool bounded, const TimeModel& time,
               std::FILE* trace) {
  Outcome o;
  const bci::ParadigmLayout layout = bci::layoutOf(r.recording);
  std::vector<bci::HeldOutSelection> held_out;  // the selections decided, as scored then
  Shown shown{stopping.max_sequences};
  std::optional<bci::LearnedSelections> fit;
  bci::Trust trust;
  std::map<int, int> before;  // the last fit's decodings (number -> choice)
  Decided decided_cells;
  double t = 0.0;
  for (int k = 1; k <= trials; ++k) {
    const int number = calibration + k;
    // Trusted before it: its selection flashes until dynamic stopping ends it, up to the
    // learning's most sequences (paradigm.learning_max_sequences); untrusted, it shows all of
    // `untrusted_sequences` (data to learn from: paradigm.learning_sequences).
    const bool trusted_before = fit && trust.trusted;
    bci::StoppingRule rule_now = stopping;
    if (trusted_before) {
      rule_now.max_sequences = extended_sequences;
    } else {
      rule_now.max_sequences = untrusted_sequences;
      rule_now.certainty = 0.0;
    }
    std::optional<int> decision;
    double certainty = 0.0, extra_s = 0.0;
    if (fit) {
      const Online d = decideOnline(fit->model, r, number, pipeline, rule_now);
      decision = d.code;
      certainty = d.certainty;
      shown.of[number] = d.sequences;
      // As the session keeps them: decided by a model fitted on as many selections as trust asks.
      if (static_cast<int>(fit->numbers.size()) >= rule.min_selections)
        held_out.push_back(d.scored);
    } else {
      shown.of[number] = untrusted_sequences;
    }
    extra_s =
        std::max(0, shown.at(number) - stopping.max_sequences) * layout.stimuli * layout.soa_s;
    const bool right = decision && *decision == r.target.at(number);
    if (decision)
      o.decisions.push_back({"objects", r.index, k, certainty, right, shown.at(number)});
    if (k >= from) {
      ++o.online_made;
      o.online_right += right;
    }
    o.right_at.push_back(right);
    // The session fits again with this selection in (as shown); the arm acts on the selection only
    // when that fit is trusted and decodes it as it was shown, and the decision was as certain as
    // dynamic stopping asks (ParadigmStage::judgeHeldSelection).
    bool sent = false;
    const auto [recording, numbers] = part(r, calibration + 1, number, false, shown);
    try {
      bci::LearnedSelections next =
          bci::learnFromUse(recording, numbers, {}, before, pipeline, training);
      bci::ScoreModel bound = next.model.score_model;
      const bci::SeparationBound separation = bci::boundByHeldOut(bound, held_out, layout);
      if (bounded) next.model.score_model = bound;
      trust = bci::judgeTrust(next, before, rule);
      const int fitted =
          !next.numbers.empty() && next.numbers.back() == number ? next.choice.back() + 1 : 0;
      sent = decision && trust.trusted && fitted == *decision && certainty >= stopping.certainty;
      if (trace)
        std::fprintf(trace, "none,%d,%d,%d,%d,%zu,%.3f,%d,%.3f,%zu,%d,%d,%.6f,%.6f,%d,%.3f,%.3f\n",
                     r.index, k, decision ? *decision : 0, r.target.at(number), next.numbers.size(),
                     next.consistency, next.beats_shuffled, next.p3_uv.value_or(0.0),
                     trust.changed.size(), trust.trusted, fitted, certainty,
                     next.posterior.empty() ? 0.0 : next.posterior.back(), shown.at(number),
                     separation.fitted, separation.held_out.value_or(-1.0));
      before.clear();
      for (size_t i = 0; i < next.numbers.size(); ++i) before[next.numbers[i]] = next.choice[i];
      fit = std::move(next);
    } catch (const std::exception&) {
      // Too little to train on yet: the model before is kept (none at first).
    }
    o.trusted_at.push_back(sent);
    // The object held, its cell is chosen by the model that trusted it (with dynamic stopping up
    // to the learning's most sequences).
    if (sent && cells) {
      bci::StoppingRule cell_rule = stopping;
      cell_rule.max_sequences = extended_sequences;
      decideCell(fit->model, *cells, k, pipeline, cell_rule, decided_cells, o);
    }
    if (sent) {
      ++o.arm_sent;
      o.arm_wrong += !right;
      if (!o.first_trusted) o.first_trusted = k;
      t += (trusted_before ? time.trial_s : time.held_then_sent_s) + extra_s;
      if (right && o.first_right_s < 0.0) o.first_right_s = t;
    } else {
      t += time.learning_trial_s + extra_s;
    }
  }
  if (fit) {
    for (size_t i = 0; i < fit->numbers.size(); ++i) {
      ++o.post_hoc_made;
      o.post_hoc_right += fit->choice[i] + 1 == r.target.at(fit->numbers[i]);
    }
  }
  return o;
}

// Decisions by the certainty they claimed, against how many were wrong (bci::reliabilityBands).
void reliability(const char* condition, const std::vector<Judged>& decisions) {
  for (const char* kind : {"objects", "cells"}) {
    std::vector<bci::ClaimedDecision> claimed;
    for (const Judged& j : decisions)
      if (std::string(j.kind) == kind) claimed.push_back({j.certainty, j.right});
    if (claimed.empty()) continue;
    std::printf("%s, %s: band        decisions  wrong  expected  95 %% of claims   verdict\n",
                condition, kind);
    for (const bci::ReliabilityBand& b : bci::reliabilityBands(claimed))
      std::printf("  [%.3f, %.3f%c  %9d  %5d  %8.2f  [%d, %d]  %s\n", b.low, b.high,
                  b.high >= 1.0 ? ']' : ')', b.decisions, b.wrong, b.expected_wrong, b.wrong_low,
                  b.wrong_high, b.verdict());
  }
}

std::string seconds(double s) {
  return s < 0 ? "never" : std::to_string(static_cast<int>(s)) + " s";
}

void line(const char* what, const Outcome& o) {
  std::printf(
      "  %-10s online %2d/%-2d  arm %2d sent, %d wrong  post hoc %2d/%-2d  first trusted %2d"
      "  first right placement %s\n",
      what, o.online_right, o.online_made, o.arm_sent, o.arm_wrong, o.post_hoc_right,
      o.post_hoc_made, o.first_trusted, seconds(o.first_right_s).c_str());
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{"Learning from use against a calibration run, replayed on copy-task recordings"};
  std::vector<std::string> files;
  int calibration = 8, trials = 30, from = 11;
  std::string trace_file;
  bool ceiling_only = false;
  int untrusted_sequences = 0;
  bool unbounded = false, independent_flashes = false;
  std::string decisions_file, scores_file;
  cli.add_option("files", files, "recordings (copy task, single stimulus)")->required();
  cli.add_option("--calibration", calibration, "cued selections of the calibration run")
      ->capture_default_str();
  cli.add_option("--trials", trials, "trials after it")->capture_default_str();
  cli.add_option("--from", from, "online accuracy counted from this trial on")
      ->capture_default_str();
  cli.add_option("--trace", trace_file,
                 "write per trial of the learning condition: file index, trial, decision, "
                 "target, selections fitted, consistency, shuffles beaten, p3 uV, changed, "
                 "trusted (after the fit with that trial in), that fit's decoding of it, the "
                 "online decision's certainty, that fit's posterior of its decoding, the "
                 "sequences shown, the fit's separation as cross-validated and as the selections "
                 "decided show it (-1: none yet); and per file, each trial decided right by the "
                 "calibrated model "
                 "and by one trained on the trials before with "
                 "their true labels (the ceiling of learning without them)");
  cli.add_flag("--ceiling-only", ceiling_only,
               "trace the calibrated model and the labels-known ceiling only (no learning: fast)");
  cli.add_option("--untrusted-sequences", untrusted_sequences,
                 "sequences an untrusted learning selection shows (0: as the session's "
                 "paradigm.learning_sequences gives them)");
  cli.add_flag("--unbounded", unbounded,
               "leave each fit's score model as its cross-validation on the labels found gives "
               "it (the session bounds its separation by the selections decided: "
               "bci/held_out_separation.h)");
  cli.add_flag("--independent-flashes", independent_flashes,
               "the calibrated model's certainty as before its two terms: every flash independent "
               "evidence (rho 0) and no selection held to the separation those decided show; to "
               "measure what the terms cost and what they buy");
  cli.add_option("--decisions", decisions_file,
                 "write every online decision: condition, kind (objects, cells), file index, "
                 "trial, certainty, right, sequences");
  cli.add_option("--scores", scores_file,
                 "write every flash's score in the calibrated condition (the calibration run's "
                 "cross-validated, the trials' by the model, all sequences recorded): file, kind "
                 "(cv, objects, cells; a 'model' row: its score model's means and SD), "
                 "selection, flash index, sample, code, target, score");
  CLI11_PARSE(cli, argc, argv);
  std::FILE* scores = scores_file.empty() ? nullptr : std::fopen(scores_file.c_str(), "w");
  std::FILE* trace = trace_file.empty() ? nullptr : std::fopen(trace_file.c_str(), "w");
  const session::SessionConfig config;
  const bci::PipelineSettings pipeline =
      bci::withMethodRate(config.classifier.pipeline, config.classifier.training.method);
  const bci::TrustRule rule{config.paradigm.learning_min_selections,
                            config.paradigm.learning_min_consistency};
  // The session's dynamic stopping (its most sequences: all a recording's selection has).
  const bci::StoppingRule stopping{config.paradigm.sequences, config.paradigm.min_sequences,
                                   config.paradigm.certainty};
  const int extended = config.paradigm.trustedMaxSequences();
  const int learning = config.paradigm.untrustedSequences();
  const TimeModel time;
  Outcome all_cal, all_none;
  std::vector<int> cal_right(static_cast<size_t>(trials)), none_right(cal_right),
      none_trusted(cal_right);
  int faster = 0, compared = 0, wrong_more = 0, ceiling_later = 0, later_both = 0;
  for (const std::string& file : files) {
    Loaded loaded = load(file);
    Replay& r = loaded.objects;
    r.index = static_cast<int>(&file - files.data());
    if (loaded.cells) loaded.cells->index = r.index;
    const Replay* cells = loaded.cells ? &*loaded.cells : nullptr;
    if (static_cast<int>(r.target.size()) < calibration + trials) {
      std::fprintf(stderr, "%s: %zu selections, fewer than %d\n", file.c_str(), r.target.size(),
                   calibration + trials);
      return 1;
    }
    const Outcome c =
        calibrated(r, cells, calibration, trials, from, pipeline, config.classifier.training,
                   stopping, time, independent_flashes, scores);
    // --ceiling-only: the learning condition skipped (reported as the calibrated one).
    const Outcome n = ceiling_only
                          ? c
                          : learnt(r, cells, calibration, trials, from, pipeline,
                                   config.classifier.training, rule, stopping, extended,
                                   untrusted_sequences > 0 ? untrusted_sequences : learning,
                                   !unbounded, time, trace);
    if (trace) {
      std::fprintf(trace, "calibrated,%d,", r.index);
      for (bool right : c.right_at) std::fputc(right ? '1' : '0', trace);
      std::fprintf(trace, "\nknown,%d,", r.index);
      for (bool right : labelsKnown(r, calibration, trials, Shown{stopping.max_sequences}, pipeline,
                                    config.classifier.training))
        std::fputc(right ? '1' : '0', trace);
      std::fputc('\n', trace);
      std::fflush(trace);
    }
    const double ceiling = certainCeiling(r, calibration, trials, pipeline,
                                          config.classifier.training, stopping, extended, time);
    std::printf("%s\n", file.c_str());
    line("calibrated", c);
    line("none", n);
    std::printf("  labels known, waiting for certainty: first right placement %s\n",
                seconds(ceiling).c_str());
    std::fflush(stdout);
    for (auto [total, one] : {std::pair{&all_cal, &c}, std::pair{&all_none, &n}}) {
      total->decisions.insert(total->decisions.end(), one->decisions.begin(), one->decisions.end());
      total->online_made += one->online_made;
      total->online_right += one->online_right;
      total->arm_sent += one->arm_sent;
      total->arm_wrong += one->arm_wrong;
      total->post_hoc_made += one->post_hoc_made;
      total->post_hoc_right += one->post_hoc_right;
    }
    for (size_t k = 0; k < static_cast<size_t>(trials); ++k) {
      cal_right[k] += c.right_at[k];
      none_right[k] += n.right_at[k];
      none_trusted[k] += n.trusted_at[k];
    }
    wrong_more += n.arm_wrong > c.arm_wrong;
    if (c.first_right_s >= 0.0) {
      ++compared;
      const bool later = n.first_right_s < 0.0 || n.first_right_s > c.first_right_s;
      faster += !later;
      const bool ceiling_late = ceiling < 0.0 || ceiling > c.first_right_s;
      ceiling_later += ceiling_late;
      later_both += later && ceiling_late;
    }
  }
  const auto rate = [](const char* what, int right, int made) {
    const bci::Interval ci = bci::wilsonInterval(right, made);
    std::printf("%-46s %4d/%-4d %.3f [%.3f, %.3f]\n", what, right, made,
                made ? static_cast<double>(right) / made : 0.0, ci.low, ci.high);
  };
  std::printf("\nall %zu recordings\n", files.size());
  rate("calibrated: online right (trials --from on)", all_cal.online_right, all_cal.online_made);
  rate("none: online right (trials --from on)", all_none.online_right, all_none.online_made);
  rate("calibrated: arm sent to a wrong object", all_cal.arm_wrong, all_cal.arm_sent);
  rate("none: arm sent to a wrong object", all_none.arm_wrong, all_none.arm_sent);
  rate("none: post hoc right (last fit)", all_none.post_hoc_right, all_none.post_hoc_made);
  std::printf("recordings where none sent the arm wrong more often: %d\n", wrong_more);
  // The learning curve: trial k decided right online, in how many recordings, and in how many the
  // arm was sent.
  std::printf(
      "\nlearning curve (of %zu recordings)\ntrial  calibrated right  none right  none arm sent\n",
      files.size());
  for (int k = 0; k < trials; ++k)
    std::printf("%5d  %16d  %10d  %12d\n", k + 1, cal_right[static_cast<size_t>(k)],
                none_right[static_cast<size_t>(k)], none_trusted[static_cast<size_t>(k)]);
  std::printf("first right placement no later without calibration: %d of %d\n", faster, compared);
  std::printf(
      "first right placement later than calibrated even with labels known (waiting for "
      "certainty): %d of %d; of the later ones without calibration: %d of %d\n",
      ceiling_later, compared, later_both, compared - faster);
  std::printf("\nreliability of the online decisions (trials 1 on)\n");
  reliability("calibrated", all_cal.decisions);
  if (!ceiling_only) reliability("none", all_none.decisions);
  if (!decisions_file.empty()) {
    std::FILE* out = std::fopen(decisions_file.c_str(), "w");
    std::fprintf(out, "condition,kind,file,trial,certainty,right,sequences\n");
    for (auto [name, outcome] : {std::pair{"calibrated", &all_cal}, std::pair{"none", &all_none}}) {
      for (const Judged& j : outcome->decisions)
        std::fprintf(out, "%s,%s,%d,%d,%.9f,%d,%d\n", name, j.kind, j.file, j.trial, j.certainty,
                     j.right, j.sequences);
    }
    std::fclose(out);
  }
  if (trace) std::fclose(trace);
  if (scores) std::fclose(scores);
  return 0;
}
