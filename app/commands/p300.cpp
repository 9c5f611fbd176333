// `arbci train` and `arbci evaluate`: P300 models from recordings, cross-validated by selection,
// and their accuracy, selections and bit rate on other recordings.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iostream>
#include <optional>
#include <set>
#include <sstream>

#include "arbci/bci/channel_quality.h"
#include "arbci/bci/classifier.h"
#include "arbci/bci/errp_feedback.h"
#include "arbci/bci/p300_dataset.h"
#include "arbci/bci/p300_model.h"
#include "arbci/bci/p300_template.h"
#include "arbci/bci/settings.h"
#include "arbci/bci/unsupervised.h"
#include "arbci/session/session_config.h"
#include "arbci/session/settings_schema.h"
#include "commands/commands.h"
#include "eeg/p300_plots.h"
#include "eeg/p300_report.h"
#include "eeg/session_evaluation.h"
#include "support/cli_error.h"
#include "support/name_list.h"
#include "support/output_path.h"
#include "support/schema_option.h"

namespace arbci::app {
namespace {

std::vector<bci::Recording> readAll(const std::vector<std::string>& files) {
  std::vector<bci::Recording> recordings;
  for (const std::string& file : files) {
    try {
      recordings.push_back(bci::readRecording(file));
    } catch (const bci::RecordingError& error) {
      throw CliError(error.what());
    }
  }
  return recordings;
}

// Flat and drifting channels of each recording, said; with `exclude`, taken out of every
// recording. Returns the report's "channels" block.
nlohmann::json checkChannels(std::vector<bci::Recording>& recordings, bool exclude) {
  std::set<std::string> flat, drifting;
  for (const bci::Recording& r : recordings) {
    for (const bci::ChannelQuality& q : bci::assessChannels(r)) {
      if (q.flat) flat.insert(q.channel);
      if (q.drifting) drifting.insert(q.channel);
    }
  }
  std::vector<std::string> bad(flat.begin(), flat.end());
  bad.insert(bad.end(), drifting.begin(), drifting.end());
  if (!bad.empty()) {
    std::cout << "channels: "
              << (flat.empty() ? "" : "flat " + joinNames({flat.begin(), flat.end()}))
              << (flat.empty() || drifting.empty() ? "" : "; ")
              << (drifting.empty() ? ""
                                   : "drifting " + joinNames({drifting.begin(), drifting.end()}))
              << (exclude ? ": excluded" : ": used (--exclude-bad-channels to leave them out)")
              << "\n";
  }
  if (exclude && !bad.empty()) {
    for (bci::Recording& r : recordings) r = bci::withoutChannels(r, bad);
  }
  return {{"flat", flat}, {"drifting", drifting}, {"excluded", exclude && !bad.empty()}};
}

// The channels checkChannels left out, with why, for the figures and erp.json.
void noteExcluded(bci::ErpCurves& erp, const nlohmann::json& quality) {
  if (!quality.value("excluded", false)) return;
  for (const char* why : {"flat", "drifting"})
    for (const auto& name : quality[why]) erp.excluded.emplace_back(name.get<std::string>(), why);
}

// --scalp-window-ms and --scalp-ms: where the scalp map is drawn (bci::ScalpTime's defaults).
struct ScalpOptions {
  std::vector<double> window_ms{bci::ScalpTime{}.from_s * 1000.0, bci::ScalpTime{}.to_s * 1000.0};
  std::optional<double> at_ms;
  bci::ScalpTime time() const {
    bci::ScalpTime t;
    t.from_s = window_ms[0] / 1000.0;
    t.to_s = window_ms[1] / 1000.0;
    if (at_ms) t.at_s = *at_ms / 1000.0;
    return t;
  }
};

void addScalpOptions(CLI::App& command, ScalpOptions& o) {
  command
      .add_option("--scalp-window-ms", o.window_ms,
                  "the scalp map's search window: it is drawn where the target - non-target "
                  "difference peaks inside it (FROM,TO after the stimulus)")
      ->expected(2)
      ->delimiter(',')
      ->capture_default_str()
      ->check(CLI::Range(-2000.0, 5000.0));
  command.add_option("--scalp-ms", o.at_ms,
                     "draw the scalp map at this time after the stimulus instead (ms)");
}

void printPlots(const std::vector<std::filesystem::path>& written) {
  bool scalp = false;
  for (const auto& file : written) {
    std::cout << "plot: " << file.string() << "\n";
    scalp |= file.filename() == "scalp.png";
  }
  if (!scalp) std::cout << "(no scalp map: fewer than 3 channels have 10-20 names)\n";
}

std::string utcNow() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

struct TrainOptions {
  std::vector<std::string> files;
  std::string out, bci2000, plots, report, scores;
  std::vector<double> window_ms;  // pipeline.window_ms
  bci::DatasetOptions dataset;    // --reject-uv, --causal
  bool exclude_bad_channels = false;
  ScalpOptions scalp;
  bci::TrainingSettings training;
  bci::PipelineSettings pipeline;
  // ErrP: the recordings' feedback events instead of their flashes.
  bool errp = false;
  bool calibration_only = false;  // only the calibration blocks' feedbacks
  std::string p300_model;         // the ErrP classifier is written inside this P300 model
  double errp_threshold = 0.0;    // errp.threshold
  bool unsupervised = false;      // learn without the recordings' labels (bci/unsupervised.h)
};

// What learning without labels found, and, where the recordings carry labels (never read by it),
// how it compares: post-hoc accuracy, the learning curve, and its AUC beside the supervised one.
void learnWithoutLabels(const TrainOptions& o, bci::P300Dataset& data) {
  bci::UnsupervisedOptions options;
  options.p300_direction = bci::p300Template(o.pipeline, data.info);
  const bci::UnsupervisedReport u = bci::evaluateWithoutLabels(data, options);
  const int n = static_cast<int>(data.selections.size());
  std::cout << "unsupervised (EM over each selection's one attended choice; the labels not read): "
            << u.fit.agreeing << " of " << u.fit.restarts
            << " starts agree on the decoding kept; held-out consistency " << u.fit.consistency
            << " (fitted without each selection, the share decoded as before); it explains "
            << u.fit.explained << " of the variance, more than " << u.fit.beats_shuffled
            << " of 9 fits with the codes shuffled (at most " << u.fit.shuffled_explained << ")\n";
  if (u.labelled) {
    std::cout << "post hoc, against the recordings' labels: " << u.right << " of " << n
              << " selections right\n";
  }
  std::cout << "learning curve (selection k decoded by the fit on selections 1..k; starts "
               "agreeing, held-out consistency):";
  for (const auto& p : u.curve) {
    char consistency[16];
    std::snprintf(consistency, sizeof consistency, "%.2f", p.consistency);
    std::cout << " " << p.selection << (u.labelled ? (p.right ? " right" : " wrong") : "") << " ("
              << p.agreeing << ", " << consistency << ")";
    if (&p != &u.curve.back()) std::cout << ",";
  }
  std::cout << "\n";
  if (u.labelled && n >= 2) {
    bci::TrainingResult supervised = bci::trainModel(data, o.pipeline, o.training);
    std::cout << "AUC against the labels, each selection scored by the fit on the others: "
              << u.cross_validated_auc << " (unsupervised) vs "
              << supervised.cross_validation.report.auc << " (" << o.training.method
              << " on the labels, cross-validated)\n";
  }
  data = bci::withLabelsFound(data, u.fit);
  std::cout << "the model below is " << o.training.method
            << " trained on the labels found (its cross-validation is against them)\n\n";
}

// The recordings' averages with each flash labelled as the fit found it (every flash known), for
// the ERP figures of what was learnt.
bci::P300Dataset averagesByLabelsFound(std::vector<bci::Recording> recordings,
                                       const bci::P300Dataset& found, const TrainOptions& o) {
  std::map<std::pair<int, std::int64_t>, bool> target;
  for (int e = 0; e < found.epochs(); ++e)
    target[{found.file[static_cast<size_t>(e)], found.sample[static_cast<size_t>(e)]}] =
        found.target[static_cast<size_t>(e)];
  for (size_t f = 0; f < recordings.size(); ++f) {
    std::vector<bci::StimulusEvent> kept;
    for (bci::StimulusEvent e : recordings[f].stimuli) {
      const auto label = target.find({static_cast<int>(f), e.sample});
      if (label == target.end()) continue;  // not learnt from
      e.target = label->second;
      e.known = true;
      kept.push_back(e);
    }
    recordings[f].stimuli = std::move(kept);
  }
  return bci::buildDataset(recordings, o.pipeline, {}, o.dataset);
}

// Every output is checked before any work: a typo in a path costs no training.
void checkOutputs(const std::string& plots, const std::vector<std::string>& files) {
  if (!plots.empty()) ensureWritableFolder(plots);
  for (const std::string& file : files) {
    if (!file.empty()) ensureWritable(file);
  }
}

// What a report says of the data: the files, the channels' check, what was left out.
nlohmann::json datasetFacts(const bci::P300Dataset& data, const nlohmann::json& channels) {
  return {{"files", data.sources},
          {"channels", channels},
          // What the averages went through (the features' filter differs only in being causal
          // where zero_phase is false).
          {"averages", analysisJson(data.erp)},
          {"rejected_epochs", data.rejected_epochs},
          {"reject_uv", data.reject_uv},
          {"unknown_flashes", data.unknown_flashes},
          {"other_code_flashes", data.other_code_flashes},
          {"interrupted_flashes", data.interrupted_flashes}};
}

void writeReportFiles(const std::string& report_path, const std::string& scores_path,
                      const bci::EvaluationReport& report, nlohmann::json extra,
                      const bci::P300Dataset& data, const std::vector<double>& scores,
                      const std::vector<int>& fold) {
  if (!report_path.empty()) {
    extra.update(reportJson(report));
    std::ofstream out(report_path);
    out << extra.dump(2) << "\n";
    if (!out) throw CliError("cannot write " + report_path);
    std::cout << "report: " << report_path << "\n";
  }
  if (!scores_path.empty()) {
    writeScoresCsv(scores_path, data, scores, fold);
    std::cout << "scores: " << scores_path << "\n";
  }
}

// Where a recording's feedbacks come from and which are used.
void printFeedbackCounts(std::ostream& out, const std::string& source,
                         const bci::FeedbackRecording& feedback, bool calibration_only) {
  const auto counts = [](const bci::FeedbackCounts& c) {
    return std::to_string(c.total()) + " feedbacks (" + std::to_string(c.errors) + " error, " +
           std::to_string(c.correct) + " correct)";
  };
  out << source << ": calibration block " << counts(feedback.calibration) << ", online "
      << counts(feedback.online);
  if (feedback.unknown > 0) out << ", " << feedback.unknown << " of unknown correctness (left out)";
  out << "; training on " << feedback.errors << " error and " << feedback.correct
      << " correct feedbacks";
  if (calibration_only)
    out << ", the calibration block's";
  else if (feedback.calibration.total() > 0 && feedback.online.total() > 0)
    out << ", both parts (--calibration-only: the calibration block's alone)";
  out << "\n";
}

// With --errp, what was not given on the command line is what a session's ErrP classifier uses
// (the embedded session's "errp"), so an offline ErrP model compares with a session's own.
void applyErrpDefaults(TrainOptions& o, const CLI::App& cmd) {
  const session::ErrpSettings errp = session::SessionConfig::load(std::nullopt).errp;
  const bci::TrainingSettings training = errp.training();
  const auto ms = [](double s) { return std::to_string(std::lround(s * 1000.0)); };
  const auto text = [](double v) {  // 20, not 20.000000
    std::ostringstream out;
    out << v;
    return out.str();
  };
  const std::vector<std::pair<const char*, std::function<std::string()>>> defaults{
      {"--method", [&] { return o.training.method = training.method; }},
      {"--xdawn-filters",
       [&] { return std::to_string(o.training.xdawn.filters = training.xdawn.filters); }},
      {"--window-ms",
       [&] {
         o.window_ms = {1000.0 * errp.window.start_s, 1000.0 * errp.window.end_s};
         return ms(errp.window.start_s) + "," + ms(errp.window.end_s);
       }},
      {"--decimate-hz", [&] { return text(o.pipeline.decimate_hz = errp.decimate_hz); }},
      {"--highpass-hz", [&] { return text(o.pipeline.filter.highpass_hz = errp.highpass_hz); }},
      {"--lowpass-hz", [&] { return text(o.pipeline.filter.lowpass_hz = errp.lowpass_hz); }},
      {"--folds", [&] { return std::to_string(o.training.folds = training.folds); }},
      {"--folds-by", [&] { return o.training.folds_by = training.folds_by; }}};
  std::string taken;
  for (const auto& [option, apply] : defaults) {
    if (cmd.count(option) == 0) taken += std::string(" ") + option + " " + apply();
  }
  if (!taken.empty())
    std::cout << "--errp: as a session's ErrP classifier where not given:" << taken << "\n";
}

void train(TrainOptions& o, const CLI::App& command) {
  o.pipeline.window = {o.window_ms[0] / 1000.0, o.window_ms[1] / 1000.0};
  checkSchemaRules(bci::trainingSchema(), bci::trainingSchema().write(o.training), command);
  checkSchemaRules(bci::pipelineSchema(), bci::pipelineSchema().write(o.pipeline), command);
  if (!bci::classifiers().at(o.training.method).make.linear && !o.bci2000.empty()) {
    std::string linear;
    for (const auto& entry : bci::classifiers().entries())
      if (entry.make.linear) linear += (linear.empty() ? "" : ", ") + entry.name;
    throw CliError("--bci2000: a " + o.training.method +
                   " model is not linear in its features, so BCI2000's LinearClassifier cannot "
                   "run it (train " +
                   linear + " for BCI2000)");
  }
  if (o.errp && o.unsupervised)
    throw CliError(
        "--unsupervised learns the P300 from its one attended choice per selection; "
        "an ErrP classifier (--errp) has no such choice");
  if (o.errp && !o.bci2000.empty())
    throw CliError("--bci2000: BCI2000 has no ErrP classifier; leave out --bci2000 with --errp");
  if (!o.errp && !o.p300_model.empty())
    throw CliError("--p300-model takes the ErrP classifier: it needs --errp");
  if (!o.errp && o.calibration_only)
    throw CliError("--calibration-only picks ErrP feedbacks: it needs --errp");
  std::optional<bci::P300Model> p300;
  if (!o.p300_model.empty()) {
    try {
      p300 = bci::P300Model::load(o.p300_model);
    } catch (const bci::ModelError& error) {
      throw CliError(error.what());
    }
  }
  checkOutputs(o.plots, {o.out, o.bci2000, o.report, o.scores});
  // Learning without labels takes the flashes whose target is not known too (a free choice).
  if (o.unsupervised) o.dataset.keep_unknown = true;
  try {
    o.pipeline = bci::withMethodRate(o.pipeline, o.training.method);
  } catch (const std::invalid_argument& error) {
    throw CliError(error.what());
  }
  const bci::Progress progress = progressLine(std::cerr);
  bci::TrainingResult result;
  bci::P300Dataset data, found_erp;
  nlohmann::json quality;
  try {
    std::vector<bci::Recording> recordings = readAll(o.files);
    if (o.errp) {
      for (bci::Recording& r : recordings) {
        bci::FeedbackRecording feedback = bci::feedbackRecording(
            r, o.calibration_only ? bci::FeedbackPart::Calibration : bci::FeedbackPart::Both);
        printFeedbackCounts(std::cout, r.source, feedback, o.calibration_only);
        r = std::move(feedback.recording);
      }
    }
    quality = checkChannels(recordings, o.exclude_bad_channels);
    data = bci::buildDataset(recordings, o.pipeline, progress, o.dataset);
    noteExcluded(data.erp, quality);
    if (o.unsupervised) {
      learnWithoutLabels(o, data);
      if (!o.plots.empty()) found_erp = averagesByLabelsFound(recordings, data, o);
    }
    result = bci::trainModel(data, o.pipeline, o.training, progress);
    if (o.unsupervised)
      result.model.provenance["labels"] = "found without labels (arbci train --unsupervised)";
  } catch (const std::invalid_argument& error) {
    throw CliError(error.what());
  }
  result.model.provenance["created"] = utcNow();
  result.model.provenance["arbci_version"] = ARBCI_VERSION;
  try {
    if (p300) {
      p300->errp = std::make_shared<const bci::P300Model>(result.model);
      p300->errp_auc = result.cross_validation.report.auc;
      p300->save(o.out);
    } else {
      result.model.save(o.out);
    }
    if (!o.bci2000.empty()) {
      std::ofstream prm(o.bci2000);
      prm << result.model.bci2000Fragment();
      if (!prm) throw CliError("cannot write " + o.bci2000);
    }
  } catch (const bci::ModelError& error) {
    throw CliError(error.what());
  }
  std::cout << "trained " << o.training.method << " on " << data.epochs() << " epochs ("
            << data.shape.channels << " channels x " << data.shape.bins << " bins) from "
            << data.sources.size() << " file(s)";
  if (data.dropped_epochs > 0)
    std::cout << "; " << data.dropped_epochs << " flashes too close to a file's end left out";
  if (o.dataset.reject_uv > 0.0) {
    std::cout << "; " << data.rejected_epochs << " epochs over " << o.dataset.reject_uv
              << " uV peak-to-peak rejected";
  }
  if (o.pipeline.zero_phase) std::cout << "; zero-phase filters (offline only)";
  std::cout << "\nthe averages (figures, erp.json): " << analysisText(data.erp);
  if (data.other_code_flashes > 0) {
    std::cout << "; " << data.other_code_flashes << " flashes with codes beyond the paradigm's "
              << data.layout.codes() << " (a session's grid) left out";
  }
  if (data.interrupted_flashes > 0) {
    std::cout << "; " << data.interrupted_flashes
              << " flashes of calibration selections the session interrupted and retook left out";
  }
  if (data.unknown_flashes > 0) {
    std::cout << "; " << data.unknown_flashes
              << " flashes whose target is not known (labelled U) left out";
  }
  const bci::CrossValidation& cv = result.cross_validation;
  std::cout << "\n\ncross-validation, " << cv.folds << " folds by " << cv.folds_by
            << (o.training.folds_by.empty() ? " (the default here; --folds-by to change)" : "")
            << ":\n";
  printReport(std::cout, cv.report, o.errp ? ReportWords::errp() : ReportWords{});
  nlohmann::json facts = datasetFacts(data, quality);
  if (o.errp) {
    // What the threshold does to the cross-validated feedbacks (a prior of 0.5 for an error).
    int caught = 0, errors = 0, vetoed = 0, correct = 0;
    for (size_t i = 0; i < cv.scores.size(); ++i) {
      if (cv.fold[i] < 0) continue;
      const bool veto = bci::errorPosterior(cv.score_model, cv.scores[i], 0.5) > o.errp_threshold;
      if (data.target[i]) {
        ++errors;
        caught += veto;
      } else {
        ++correct;
        vetoed += veto;
      }
    }
    std::cout << "at threshold " << o.errp_threshold << " (prior of an error 0.5): " << caught
              << " of " << errors << " errors caught, " << vetoed << " of " << correct
              << " correct feedbacks vetoed\n";
    facts["errp_confusion"] = {
        {"threshold", o.errp_threshold}, {"prior_error", 0.5}, {"errors", errors},
        {"errors_caught", caught},       {"correct", correct}, {"correct_vetoed", vetoed}};
  }
  facts.update({{"command", "train"},
                {"method", o.training.method},
                {"folds", cv.folds},
                {"folds_by", cv.folds_by},
                {"zero_phase", o.pipeline.zero_phase}});
  writeReportFiles(o.report, o.scores, cv.report, facts, data, cv.scores, cv.fold);
  if (!o.plots.empty()) {
    const auto written = writeP300Plots(
        o.plots, data, result.cross_validation.report, "cross-validated " + o.training.method,
        o.errp ? ClassNames{"error", "correct"} : ClassNames{}, o.scalp.time());
    printPlots(written);
    if (o.unsupervised) {
      // Beside the averages by the recordings' labels (where they carry them): by the labels
      // found, the ERP the model learnt.
      // Its accuracy figure would score the model against the labels it was trained to find
      // (agreement, not accuracy): only the averages and the scalp map are kept.
      std::vector<std::filesystem::path> written_found;
      for (const auto& path : writeP300Plots(std::filesystem::path(o.plots) / "labels-found",
                                             found_erp, result.cross_validation.report,
                                             "labels found without labels, " + o.training.method,
                                             {}, o.scalp.time())) {
        if (path.filename() == "accuracy.png") {
          std::filesystem::remove(path);
        } else {
          written_found.push_back(path);
        }
      }
      printPlots(written_found);
    }
  }
  std::cout << "model: " << o.out << "\n";
  if (!o.bci2000.empty()) std::cout << "BCI2000 parameters: " << o.bci2000 << "\n";
}

struct EvaluateOptions {
  std::string model, plots, report, scores;
  bci::DatasetOptions dataset;  // --reject-uv, --causal
  std::vector<std::string> files;
  int sequences = 0;
  bci::StoppingRule dynamic = bci::kOfflineStopping;
  std::string align = "per-file";
  ScalpOptions scalp;
  bool replay_stopping = false;  // session recordings: dynamic stopping replayed
};

// Whether the model was trained on `recording`'s calibration run: its provenance names the file,
// or says it is the session's own model and lies beside it.
bool trainedOn(const bci::P300Model& model, const std::string& model_file,
               const bci::Recording& recording) {
  namespace fs = std::filesystem;
  std::error_code error;
  const fs::path file = fs::weakly_canonical(recording.source, error);
  for (const auto& f : model.provenance.value("training_files", nlohmann::json::array())) {
    const std::string name = f.get<std::string>();
    if (name == "this session's calibration run" &&
        fs::weakly_canonical(model_file, error).parent_path() == file.parent_path())
      return true;
    if (fs::weakly_canonical(name, error) == file) return true;
  }
  return false;
}

// Session recordings: the calibration run apart (in-sample when the model was trained on it) and
// every online selection decided as the session decides it (eeg/session_evaluation.h).
void evaluateSessions(const EvaluateOptions& o, const bci::P300Model& model,
                      const std::vector<bci::Recording>& recordings) {
  // The session's dynamic stopping, replayed only when asked (--replay-stopping): a session's
  // recording holds the flashes it showed, which it decided on.
  const session::SessionConfig config;
  const bci::StoppingRule rule{0, config.paradigm.min_sequences,
                               o.replay_stopping ? config.paradigm.certainty : 0.0};
  nlohmann::json report = {
      {"command", "evaluate"}, {"model", o.model}, {"sessions", nlohmann::json::array()}};
  for (const bci::Recording& r : recordings) {
    SessionEvaluation e = evaluateSession(model, r, rule, o.sequences);
    e.in_sample = trainedOn(model, o.model, r);
    printSessionEvaluation(std::cout, e, rule);
    nlohmann::json online = nlohmann::json::array();
    for (const OnlineDecision& d : e.online) {
      online.push_back({{"kind", bci::toString(d.kind)},
                        {"trial", d.trial},
                        {"selection", d.number},
                        {"codes", d.decision.codes},
                        {"certainty", d.decision.certainty},
                        {"sequences", d.sequences},
                        {"attended", d.truth},
                        {"right", d.truth.empty() ? nlohmann::json() : nlohmann::json(d.right())}});
    }
    report["sessions"].push_back({{"source", e.source},
                                  {"calibration",
                                   {{"selections", e.calibration_selections},
                                    {"right", e.calibration_right},
                                    {"in_sample", e.in_sample}}},
                                  {"online", online}});
  }
  if (!o.report.empty()) {
    std::ofstream out(o.report);
    out << report.dump(2) << "\n";
    if (!out) throw CliError(o.report + ": cannot write the report");
  }
}

void evaluate(EvaluateOptions& o) {
  checkOutputs(o.plots, {o.report, o.scores});
  bci::P300Model model;
  try {
    model = bci::P300Model::load(o.model);
  } catch (const bci::ModelError& error) {
    throw CliError(error.what());
  }
  std::vector<bci::Recording> recordings = readAll(o.files);
  const auto sessions = std::count_if(recordings.begin(), recordings.end(), isSessionRecording);
  if (sessions > 0 && sessions < static_cast<long>(recordings.size()))
    throw CliError(
        "evaluate session recordings (their calibration run and online trials scored apart) "
        "apart from copy-task recordings");
  const nlohmann::json quality = checkChannels(recordings, false);
  for (const bci::Recording& r : recordings) {
    try {
      model.checkCompatible(r.info, r.source);
    } catch (const bci::ModelError& error) {
      throw CliError(error.what());
    }
    // A model picks among its layout's choices: scored on another layout's selections, its
    // accuracy would mean nothing.
    const bci::ParadigmLayout layout = bci::layoutOf(r);
    const bool row_column = layout.kind == bci::ParadigmLayout::Kind::RowColumn;
    const bool differs =
        layout.kind != model.layout.kind ||
        (row_column ? layout.rows != model.layout.rows || layout.columns != model.layout.columns
                    : layout.stimuli > model.layout.stimuli);
    if (differs)
      throw CliError(r.source + " is a " + layout.describeShape() +
                     " recording, but the model was trained on " + model.layout.describeShape() +
                     " recordings; evaluate it on recordings of its layout (an XDF carries its "
                     "layout only from ARBCI's marker stream)");
  }
  if (sessions > 0) {
    if (!o.plots.empty() || !o.scores.empty())
      throw CliError("--plots and --scores are for copy-task recordings, not a session's");
    try {
      evaluateSessions(o, model, recordings);
    } catch (const std::invalid_argument& error) {
      throw CliError(error.what());
    }
    return;
  }
  try {
    bci::P300Dataset data = bci::buildDataset(recordings, model.pipeline, {}, o.dataset);
    if (o.dataset.reject_uv > 0.0) {
      std::cout << data.rejected_epochs << " epochs over " << o.dataset.reject_uv
                << " uV peak-to-peak rejected\n";
    }
    std::vector<double> scores(static_cast<size_t>(data.epochs()));
    for (int i = 0; i < data.epochs(); ++i)
      scores[static_cast<size_t>(i)] = model.classifier->score(data.features.row(i).transpose());
    std::vector<double> shifts;
    if (o.align == "per-file") shifts = bci::alignScoresPerFile(data, scores, model.score_model);
    if (o.sequences > 0) {
      for (auto& s : data.selections) {
        std::erase_if(s.epochs, [&](int row) {
          return data.sequence[static_cast<size_t>(row)] >= o.sequences;
        });
      }
    }
    o.dynamic.max_sequences =
        std::min(o.dynamic.max_sequences, o.sequences > 0 ? o.sequences : o.dynamic.max_sequences);
    const bci::EvaluationReport report =
        bci::evaluateScores(data, scores, model.score_model, o.dynamic);
    std::cout << "model: " << o.model << " (" << model.method << ", trained on";
    for (const auto& f : model.provenance.value("training_files", nlohmann::json::array()))
      std::cout << " " << f.get<std::string>();
    std::cout << ")\n";
    if (o.align == "per-file" && std::isnan(model.score_model.median)) {
      std::cout << "scores not aligned: the model predates the score median (train it again)\n";
    } else if (o.align == "per-file") {
      std::cout << "scores aligned per file to the training median (--align-scores none: off):";
      for (size_t f = 0; f < shifts.size(); ++f)
        std::cout << (f ? "," : "") << " " << std::showpos << std::fixed << std::setprecision(3)
                  << shifts[f] << std::noshowpos << " (" << data.sources[f] << ")";
      std::cout.unsetf(std::ios::fixed);
      std::cout << "\n";
    }
    std::cout << "the averages (figures, erp.json): " << analysisText(data.erp) << "\n";
    printReport(std::cout, report);
    nlohmann::json facts = datasetFacts(data, quality);
    facts.update({{"command", "evaluate"},
                  {"method", model.method},
                  {"model", o.model},
                  {"align_scores", o.align},
                  {"zero_phase", model.pipeline.zero_phase}});
    writeReportFiles(o.report, o.scores, report, facts, data, scores, {});
    if (!o.plots.empty()) {
      printPlots(
          writeP300Plots(o.plots, data, report, "evaluated " + model.method, {}, o.scalp.time()));
    }
  } catch (const std::invalid_argument& error) {
    throw CliError(error.what());
  }
}

// Each method with what it takes where a setting leaves it to the method (0): its features' rate
// and its spatial filters, as its registry entry says.
std::string methodsHelp() {
  std::string out = "each method's own (where --decimate-hz or --xdawn-filters is 0): ";
  bool first = true;
  for (const auto& e : bci::classifiers().entries()) {
    out += (first ? "" : ", ") + e.name + " " + core::formatNumber(e.make.feature_rate_hz) + " Hz";
    if (e.make.xdawn_filters > 0)
      out += " and " + std::to_string(e.make.xdawn_filters) + " spatial filter" +
             (e.make.xdawn_filters > 1 ? "s" : "") + (e.name == "riemann" ? " per class" : "");
    if (!e.make.linear) out += " (not linear: no --bci2000)";
    first = false;
  }
  return out;
}

// Offline dynamic stopping (the bit rate reported with it): the paradigm's keys, with the
// offline figures' own rule (bci::kOfflineStopping) as their defaults.
void addOfflineStopping(CLI::App& command, bci::StoppingRule& rule, bool min_sequences) {
  const std::string why = "offline stopping (bci::kOfflineStopping), not the session's";
  schemaOptionOwnDefault(command, "--certainty", rule.certainty,
                         session::sessionKey("paradigm.certainty"), bci::kOfflineStopping.certainty,
                         why);
  if (min_sequences)
    schemaOptionOwnDefault(command, "--min-sequences", rule.min_sequences,
                           session::sessionKey("paradigm.min_sequences"),
                           bci::kOfflineStopping.min_sequences, why);
}

void addDatasetOptions(CLI::App& command, bci::DatasetOptions& dataset) {
  command.add_flag_function(
      "--causal",
      [&dataset](std::int64_t) { dataset.erp_filter = bci::DatasetOptions::ErpFilter::AsFeatures; },
      "ERP figures filtered as the features (causal, what the online classifier sees) "
      "instead of zero-phase (the response's true latency and shape)");
  command
      .add_option("--reject-uv", dataset.reject_uv,
                  "leave out epochs whose filtered peak-to-peak amplitude exceeds this (0: keep "
                  "all)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1e7));
}

}  // namespace

void addP300Commands(CLI::App& root, int& exit_code) {
  auto t = std::make_shared<TrainOptions>();
  CLI::App* train_cmd = root.add_subcommand(
      "train",
      "Train a P300 model (--method: one of the classifiers, docs/settings.md) on\n"
      "recordings with known targets (BCI2000 .dat, ARBCI BDF+), cross-validated\n"
      "by selection. Options not given take a session's defaults (arbci settings).");
  train_cmd->add_option("FILES", t->files, "training recordings")->required();
  const auto& training = bci::trainingSchema();
  const auto& pipeline = bci::pipelineSchema();
  schemaOption(*train_cmd, "--method", t->training.method, training.at("method"), methodsHelp());
  train_cmd->add_option("--out", t->out, "model file to write (JSON)")->required();
  schemaOption(*train_cmd, "--channels", t->pipeline.channels, pipeline.at("channels"),
               "comma-separated");
  schemaOption(*train_cmd, "--window-ms", t->window_ms, pipeline.at("window_ms"),
               "START,END after the stimulus");
  schemaOption(*train_cmd, "--decimate-hz", t->pipeline.decimate_hz, pipeline.at("decimate_hz"),
               "at most the signal's rate");
  schemaOption(*train_cmd, "--highpass-hz", t->pipeline.filter.highpass_hz,
               pipeline.at("highpass_hz"));
  schemaOption(*train_cmd, "--lowpass-hz", t->pipeline.filter.lowpass_hz,
               pipeline.at("lowpass_hz"));
  schemaOption(*train_cmd, "--notch-hz", t->pipeline.filter.notch_hz, pipeline.at("notch_hz"));
  schemaOption(*train_cmd, "--notch-q", t->pipeline.filter.notch_q, pipeline.at("notch_q"));
  schemaOption(*train_cmd, "--filter-order", t->pipeline.filter.order, pipeline.at("filter_order"));
  schemaFlag(*train_cmd, "--car", t->pipeline.filter.common_average, pipeline.at("common_average"));
  schemaFlag(*train_cmd, "--zero-phase", t->pipeline.zero_phase, pipeline.at("zero_phase"),
             "the model says so, and a session filters causally");
  addDatasetOptions(*train_cmd, t->dataset);
  train_cmd->add_flag("--exclude-bad-channels", t->exclude_bad_channels,
                      "leave out flat (SD < 0.5 uV) and drifting (SD > 20x the median channel's) "
                      "channels, which are always reported");
  // The session's calibration folds (classifier.folds), as "options not given take a session's
  // defaults" says; an offline analysis may ask for more.
  schemaOption(*train_cmd, "--folds", t->training.folds, session::sessionKey("classifier.folds"),
               "here: any recordings' cross-validation; at most one per selection or file");
  schemaOption(*train_cmd, "--folds-by", t->training.folds_by, training.at("folds_by"));
  train_cmd->add_flag("--unsupervised", t->unsupervised,
                      "learn without the recordings' target labels: EM over each selection's one "
                      "attended choice (docs/classification.md); reports post-hoc accuracy, the "
                      "learning curve and the AUC beside the supervised one where labels exist");
  train_cmd->add_flag("--errp", t->errp,
                      "train the error-related-potential classifier on the recordings' feedback "
                      "events (Feedback ... correct|error; a session with errp.enabled records "
                      "them) instead of a P300 model on their flashes; options not given take "
                      "the embedded session's ErrP defaults (it prints which)");
  train_cmd->add_flag("--calibration-only", t->calibration_only,
                      "with --errp: only the calibration block's feedbacks (those before the "
                      "session trained), not the online selections'");
  train_cmd->add_option("--p300-model", t->p300_model,
                        "with --errp: write the ErrP classifier inside this P300 model (a session "
                        "needs both in one file) to --out");
  schemaOption(*train_cmd, "--threshold", t->errp_threshold,
               session::errpOwnSchema().at("threshold"), "with --errp: for the confusion printed");
  train_cmd->add_option("--report", t->report,
                        "also write the cross-validation report as JSON (everything printed)");
  train_cmd->add_option("--scores", t->scores,
                        "also write the out-of-fold score of every flash as CSV "
                        "(file,sample,code,label,score,fold)");
  schemaOption(*train_cmd, "--p-enter", t->training.swlda.p_enter, training.at("p_enter"));
  schemaOption(*train_cmd, "--p-remove", t->training.swlda.p_remove, training.at("p_remove"));
  schemaOption(*train_cmd, "--max-features", t->training.swlda.max_features,
               training.at("max_features"));
  schemaOption(*train_cmd, "--xdawn-filters", t->training.xdawn.filters,
               training.at("xdawn_filters"), "at most the number of channels");
  schemaOption(*train_cmd, "--shift-ms", t->training.shift_ms, training.at("shift_ms"));
  addOfflineStopping(*train_cmd, t->training.dynamic, false);
  train_cmd->add_option("--bci2000", t->bci2000,
                        "also write the model as a BCI2000 parameter fragment (.prm)");
  train_cmd->add_option("--plots", t->plots,
                        "folder for PNG plots (ERPs; accuracy and bit rate by sequences)");
  addScalpOptions(*train_cmd, t->scalp);
  train_cmd->callback([t, train_cmd, &exit_code] {
    if (t->errp) applyErrpDefaults(*t, *train_cmd);
    train(*t, *train_cmd);
    exit_code = 0;
  });

  auto e = std::make_shared<EvaluateOptions>();
  CLI::App* eval_cmd =
      root.add_subcommand("evaluate",
                          "Apply a P300 model to recordings: selections, accuracy by number of\n"
                          "sequences, bit rate, and dynamic stopping. A session's recording is\n"
                          "split where the session marked its selections: the calibration run\n"
                          "apart (in-sample when the model was trained on it), each online\n"
                          "selection decided as the session decides (paradigm.certainty,\n"
                          "paradigm.min_sequences), with the certainty each claimed.");
  eval_cmd->add_option("--model", e->model, "model file (from arbci train)")->required();
  eval_cmd->add_option("FILES", e->files, "recordings to evaluate")->required();
  eval_cmd
      ->add_option("--sequences", e->sequences,
                   "use at most this many sequences per selection (0: all)")
      ->check(CLI::Range(0, 1000));
  addOfflineStopping(*eval_cmd, e->dynamic, true);
  eval_cmd->add_option("--plots", e->plots, "folder for PNG plots");
  addScalpOptions(*eval_cmd, e->scalp);
  eval_cmd
      ->add_option("--align-scores", e->align,
                   "per-file: shift each file's scores so their median is the training scores' "
                   "(scores drift between sessions); none: as the model gives them")
      ->capture_default_str()
      ->check(CLI::IsMember({"per-file", "none"}));
  addDatasetOptions(*eval_cmd, e->dataset);
  eval_cmd->add_flag(
      "--replay-stopping", e->replay_stopping,
      "session recordings: decide each online selection with the session's "
      "dynamic stopping (paradigm.certainty from paradigm.min_sequences) replayed on "
      "its flashes, for a recording that holds every sequence (arbci eeg simulate "
      "--trials); without it, on every flash recorded, as the session decided");
  eval_cmd->add_option("--report", e->report, "also write the report as JSON (everything printed)");
  eval_cmd->add_option("--scores", e->scores,
                       "also write every flash's score as CSV (file,sample,code,label,score,fold)");
  eval_cmd->callback([e, &exit_code] {
    evaluate(*e);
    exit_code = 0;
  });
}

}  // namespace arbci::app
