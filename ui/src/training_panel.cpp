// The Classifier training panel: recordings, method and parameters; training with progress on a
// worker thread; the ERP averages and accuracy by sequences; saving the model and using it in the
// session. Without a model trained here it shows the session's own model and what it was trained
// on (its calibration run's averages and cross-validation).
#include <imgui.h>

#include <cfloat>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <future>
#include <mutex>
#include <optional>
#include <sstream>

#include "arbci/bci/evaluation.h"
#include "arbci/bci/p300_dataset.h"
#include "arbci/bci/p300_model.h"
#include "arbci/session/trust_report.h"
#include "arbci/ui/panel_registry.h"
#include "erp_plots.h"
#include "evaluation_plots.h"
#include "widgets.h"

namespace arbci::ui {
namespace {

class TrainingPanel final : public Panel {
 public:
  ~TrainingPanel() override;
  const char* title() const override { return "Classifier training"; }
  void draw(const PanelInput& in) override;
  void setRecordings(const std::string& files);
  // Trains as the button does; `wait` blocks until the result is in.
  void train(const PanelInput& in, bool wait);

 private:
  struct Outcome {
    std::optional<bci::TrainingResult> result;
    std::optional<bci::P300Dataset> data;
    std::string error;
  };
  void startTraining(const PanelInput& in);
  void initialise(const PanelInput& in);
  void controls(const PanelInput& in);
  void collect();
  void sessionModel(const PanelInput& in);
  void review(const PanelInput& in, const session::ParadigmPart::Review& review);
  void drawSessionErps(const PanelInput& in);
  void errpModel(const PanelInput& in);
  void trainedHere(const PanelInput& in);
  char files_[1024] = "";
  char save_path_[256] = "model.json";
  int method_ = 0;  // in bci::classifiers()
  float window_end_ms_ = 0.0f, decimate_hz_ = 0.0f;
  bool initialised_ = false;  // from the session's settings, on first use
  std::atomic<double> progress_{0.0};
  std::mutex stage_mutex_;
  std::string stage_;
  std::future<Outcome> training_;
  std::optional<Outcome> outcome_;
  std::string message_;
};

TrainingPanel::~TrainingPanel() {
  if (training_.valid()) training_.wait();
}

// The session's own settings are where the panel starts, whether it is drawn or asked to train
// first (a screenshot trains before the first frame).
void TrainingPanel::initialise(const PanelInput& in) {
  if (initialised_) return;
  const bci::TrainingSettings& training = in.settings.classifier.training;
  const bci::PipelineSettings& pipeline = in.settings.classifier.pipeline;
  const auto& entries = bci::classifiers().entries();
  for (size_t i = 0; i < entries.size(); ++i)
    if (entries[i].name == training.method) method_ = static_cast<int>(i);
  window_end_ms_ = static_cast<float>(pipeline.window.end_s * 1000.0);
  decimate_hz_ = static_cast<float>(pipeline.decimate_hz);
  initialised_ = true;
}

void TrainingPanel::startTraining(const PanelInput& in) {
  initialise(in);
  std::vector<std::string> files;
  std::istringstream named(files_);
  std::string file;
  while (named >> file) files.push_back(file);
  if (files.empty()) {
    message_ = "name at least one recording (BCI2000 .dat or ARBCI .bdf)";
    return;
  }
  // The session's classifier settings, with what the panel changes.
  bci::TrainingSettings settings = in.settings.classifier.training;
  settings.method = bci::classifiers().entries().at(static_cast<size_t>(method_)).name;
  bci::PipelineSettings pipeline = in.settings.classifier.pipeline;
  pipeline.window.end_s = window_end_ms_ / 1000.0;
  pipeline.decimate_hz = decimate_hz_;
  pipeline = bci::withMethodRate(pipeline, settings.method);
  progress_ = 0.0;
  message_.clear();
  outcome_.reset();
  training_ = std::async(std::launch::async, [this, files, settings, pipeline] {
    Outcome outcome;
    try {
      std::vector<bci::Recording> recordings;
      for (const std::string& f : files) recordings.push_back(bci::readRecording(f));
      const bci::Progress progress = [this](double fraction, const std::string& stage) {
        progress_ = fraction;
        std::lock_guard lock(stage_mutex_);
        stage_ = stage;
      };
      outcome.data = bci::buildDataset(recordings, pipeline, progress);
      outcome.result = bci::trainModel(*outcome.data, pipeline, settings, progress);
    } catch (const std::exception& error) {
      outcome.error = error.what();
    }
    return outcome;
  });
}

void TrainingPanel::setRecordings(const std::string& files) {
  std::snprintf(files_, sizeof files_, "%s", files.c_str());
}

void TrainingPanel::train(const PanelInput& in, bool wait) {
  startTraining(in);
  if (wait && training_.valid()) {
    training_.wait();
    collect();
  }
}

void TrainingPanel::collect() {
  if (training_.valid() &&
      training_.wait_for(std::chrono::seconds(0)) == std::future_status::ready) {
    outcome_ = training_.get();
    if (!outcome_->error.empty()) message_ = outcome_->error;
  }
}

// The averages the session's own classifiers were trained on, the ErrP one beside the P300 one.
void TrainingPanel::drawSessionErps(const PanelInput& in) {
  const auto& p300 = in.record.p300.erp;
  const auto& errp = in.record.errp.erp;
  if (!p300 && !errp) return;
  const int columns = p300 && errp ? 2 : 1;
  if (!ImGui::BeginTable("session erps", columns, ImGuiTableFlags_SizingStretchSame)) return;
  if (p300) {
    ImGui::TableNextColumn();
    ImGui::PushID("p300");
    heading("P300: the calibration run's flashes (baseline-corrected)");
    drawErpPlots(*p300);
    ImGui::PopID();
  }
  if (errp) {
    ImGui::TableNextColumn();
    ImGui::PushID("errp");
    heading("ErrP: the feedback block, error against correct feedback");
    drawErpPlots(*errp, "error", "correct");
    ImGui::PopID();
  }
  ImGui::EndTable();
}

void TrainingPanel::draw(const PanelInput& in) {
  // The session waits on the review: it comes first.
  if (const auto& r = in.record.paradigm.review) review(in, *r);
  controls(in);
  // The session's own model when nothing was trained here.
  if (!outcome_ || !outcome_->result) {
    sessionModel(in);
  } else {
    trainedHere(in);
  }
}

void TrainingPanel::controls(const PanelInput& in) {
  pathInput("recordings (BCI2000 .dat, GDF, EDF, BDF; several: separated by spaces)", files_,
            sizeof files_, ".dat .gdf .edf .bdf",
            "the recordings to train on; Browse picks one from the folder of the last");
  initialise(in);
  const auto& methods = bci::classifiers().entries();
  ImGui::TextUnformatted("method");
  ImGui::SetNextItemWidth(-FLT_MIN);
  if (ImGui::BeginCombo("##method", methods.at(static_cast<size_t>(method_)).name.c_str())) {
    for (size_t i = 0; i < methods.size(); ++i) {
      if (ImGui::Selectable(methods[i].name.c_str(), static_cast<int>(i) == method_))
        method_ = static_cast<int>(i);
      if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", methods[i].doc.c_str());
    }
    ImGui::EndCombo();
  }
  ImGui::TextUnformatted("window end (ms)");
  ImGui::SetNextItemWidth(-FLT_MIN);
  ImGui::SliderFloat("##window end", &window_end_ms_, 300.0f, 1200.0f, "%.0f");
  ImGui::TextUnformatted("decimate to (Hz)");
  bool own_rate = decimate_hz_ <= 0.0f;  // 0: the method's own rate
  if (ImGui::Checkbox("the method's own", &own_rate)) {
    const std::string& method = methods.at(static_cast<size_t>(method_)).name;
    decimate_hz_ =
        own_rate
            ? 0.0f
            : static_cast<float>(bci::withMethodRate(bci::PipelineSettings{}, method).decimate_hz);
  }
  if (!own_rate) {
    ImGui::SameLine();
    ImGui::SetNextItemWidth(-FLT_MIN);
    ImGui::SliderFloat("##decimate", &decimate_hz_, 10.0f, 128.0f, "%.0f Hz");
  }
  collect();
  const bool running = training_.valid();
  const bool named = std::string(files_).find_first_not_of(" \t\n") != std::string::npos;
  if (button("Train", running  ? "training is running"
                      : !named ? "name at least one recording above"
                               : ""))
    startTraining(in);
  if (running) {
    std::lock_guard lock(stage_mutex_);
    ImGui::SameLine();
    ImGui::ProgressBar(static_cast<float>(progress_.load()), ImVec2(-1, 0), stage_.c_str());
  }
  if (!message_.empty()) ImGui::TextWrapped("%s", message_.c_str());
}

// The calibration review: what the model does on the calibration run (below: its ERP and
// cross-validation), and the experimenter's decision before any online trial.
void TrainingPanel::review(const PanelInput& in, const session::ParadigmPart::Review& r) {
  heading("calibration review: go online with this model?");
  // Red below the lab's minimum, amber under what the simulated default subject reaches, green
  // above: never green by default.
  const ImVec4 colour = r.below ? ImVec4(1.0f, 0.45f, 0.3f, 1.0f)
                        : r.auc < session::kSimulatedSubjectAuc.low
                            ? ImVec4(1.0f, 0.75f, 0.3f, 1.0f)
                            : ImVec4(0.5f, 0.9f, 0.5f, 1.0f);
  // The AUC beside what chance gives and what the simulated default subject reaches: a figure a
  // new experimenter can judge.
  std::string text = "calibration run " + std::to_string(r.round) + ": " +
                     session::aucReference(r.auc, r.auc_low, r.auc_high, r.targets, r.others) +
                     ". ";
  if (r.below) {
    char minimum[160];
    std::snprintf(minimum, sizeof minimum,
                  "Below the lab's minimum %.3f (gates.min_auc): Recalibrate, or go online on "
                  "your own judgement.",
                  r.min_auc);
    text += minimum;
  } else {
    text += "The ERP and the accuracy by sequences are below.";
  }
  colouredWrapped(colour, text);
  if (button(r.below ? "Go online anyway" : "Go online"))
    in.requests.post(session::GoOnlineRequest{});
  ImGui::SameLine();
  if (button("Recalibrate")) in.requests.post(session::RecalibrateRequest{});
  ImGui::Separator();
}

void TrainingPanel::sessionModel(const PanelInput& in) {
  const bci::P300Model* current = in.record.p300.model.get();
  if (current) {
    ImGui::TextWrapped(
        "session model: %s, trained on %s", current->method.c_str(),
        current->provenance.value("training_files", nlohmann::json::array()).dump().c_str());
    errpModel(in);
  } else {
    ImGui::TextDisabled("no model yet: the session trains one after its calibration run");
  }
  // How well it did on the calibration run, cross-validated, before any online selection.
  if (const auto& calibration = in.record.paradigm.calibration) {
    heading("the session's calibration run, cross-validated (before going online)");
    drawEvaluation(*calibration);
  }
  drawSessionErps(in);
}

void TrainingPanel::errpModel(const PanelInput& in) {
  const bci::P300Model* errp = in.record.errp.model.get();
  if (!in.settings.paradigm.errp && !errp) return;
  if (!errp) {
    ImGui::TextDisabled(
        "ErrP classifier: none yet (trained after the calibration run's feedback block); until "
        "then selections are executed unchecked");
    return;
  }
  std::string channels;
  for (const auto& c : errp->pipeline.channels) channels += (channels.empty() ? "" : ", ") + c;
  const double auc = in.record.errp.auc;
  ImGui::TextWrapped(
      "ErrP classifier: %s on %s, %.0f-%.0f Hz, %.0f-%.0f ms after the feedback; cross-validated "
      "AUC %.3f; a selection is rejected above a posterior of error of %.2f",
      errp->method.c_str(), channels.c_str(), errp->pipeline.filter.highpass_hz,
      errp->pipeline.filter.lowpass_hz, 1000.0 * errp->pipeline.window.start_s,
      1000.0 * errp->pipeline.window.end_s, auc, in.settings.errp.threshold);
}

void TrainingPanel::trainedHere(const PanelInput& in) {
  const bci::TrainingResult& r = *outcome_->result;
  const bci::EvaluationReport& cv = r.cross_validation.report;
  heading("cross-validated on the recordings");
  ImGui::TextWrapped("%d folds by %s", r.cross_validation.folds,
                     r.cross_validation.folds_by.c_str());
  drawEvaluation(cv);
  heading("ERP averages (baseline-corrected), as arbci train --plots draws them");
  drawErpPlots(outcome_->data->erp);
  drawSignedR2(outcome_->data->erp);
  drawScalpMap(outcome_->data->erp);
  pathInput("model file (.json)", save_path_, sizeof save_path_, ".json",
            "where Save model writes the trained model");
  if (button("Save model")) {
    try {
      r.model.save(save_path_);
      message_ = std::string("saved ") + save_path_;
    } catch (const std::exception& error) {
      message_ = error.what();
    }
  }
  ImGui::SameLine();
  if (button("Use in the session")) {
    try {
      in.requests.post(session::UseModelRequest{std::make_shared<const bci::P300Model>(r.model)});
      message_ = "the session now uses this model";
    } catch (const std::exception& error) {
      message_ = error.what();
    }
  }
}

bool onlineTrials(const session::CycleRecord& r) {
  return r.paradigm.phase == bci::Phase::ObjectFlashing;
}

// The session's own recording, trained on in the panel as a person would.
void rehearseTraining(Panel& panel, const ShotSteps& steps) {
  auto& p = static_cast<TrainingPanel&>(panel);
  p.setRecordings((steps.folder / "recording.bdf").string());
  p.train(steps.input(), true);
}

}  // namespace

PanelRegistry::Entry trainingPanel() {
  PanelParts parts{[] { return std::make_unique<TrainingPanel>(); }, false};
  parts.shots.push_back({"training", "the session's recording trained on in the panel",
                         onlineTrials, rehearseTraining});
  // With ErrPs on, the ErrP classifier's averages beside the P300 one's.
  parts.shots.push_back(
      {"session-model", "the model the session trained after its calibration", onlineTrials});
  return {"training", "train a classifier on recordings; the ERPs, AUC and accuracy by sequences",
          std::move(parts)};
}

}  // namespace arbci::ui
