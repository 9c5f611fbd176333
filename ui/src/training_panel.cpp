#include <imgui.h>

#include <cfloat>

#include <algorithm>
#include <cstdio>
#include <sstream>

#include "arbci/bci/p300_model.h"
#include "arbci/ui/panel_registry.h"
#include "arbci/ui/panels.h"
#include "erp_plots.h"
#include "evaluation_plots.h"
#include "widgets.h"

namespace arbci::ui {

TrainingPanel::~TrainingPanel() {
  if (training_.valid()) training_.wait();
}

// The session's own settings are where the panel starts, whether it is drawn or asked to train
// first (a screenshot trains before the first frame).
void TrainingPanel::initialise() {
  if (initialised_) return;
  const bci::TrainingSettings training = model_.trainingSettings();
  const bci::PipelineSettings pipeline = model_.pipelineSettings();
  const auto& entries = bci::classifiers().entries();
  for (size_t i = 0; i < entries.size(); ++i)
    if (entries[i].name == training.method) method_ = static_cast<int>(i);
  window_end_ms_ = static_cast<float>(pipeline.window.end_s * 1000.0);
  decimate_hz_ = static_cast<float>(pipeline.decimate_hz);
  initialised_ = true;
}

void TrainingPanel::startTraining() {
  initialise();
  std::vector<std::string> files;
  std::istringstream in(files_);
  std::string file;
  while (in >> file) files.push_back(file);
  if (files.empty()) {
    message_ = "name at least one recording (BCI2000 .dat or ARBCI .bdf)";
    return;
  }
  // The session's classifier settings, with what the panel changes.
  bci::TrainingSettings settings = model_.trainingSettings();
  settings.method = bci::classifiers().entries().at(static_cast<size_t>(method_)).name;
  bci::PipelineSettings pipeline = model_.pipelineSettings();
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

void TrainingPanel::train(bool wait) {
  startTraining();
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
void TrainingPanel::drawSessionErps() {
  const auto p300 = model_.sessionErp();
  const auto errp = model_.sessionErrpErp();
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

void TrainingPanel::draw() {
  pathInput("recordings (BCI2000 .dat, GDF, EDF, BDF; several: separated by spaces)", files_,
            sizeof files_, ".dat .gdf .edf .bdf",
            "the recordings to train on; Browse picks one from the folder of the last");
  initialise();
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
    startTraining();
  if (running) {
    std::lock_guard lock(stage_mutex_);
    ImGui::SameLine();
    ImGui::ProgressBar(static_cast<float>(progress_.load()), ImVec2(-1, 0), stage_.c_str());
  }
  if (!message_.empty()) ImGui::TextWrapped("%s", message_.c_str());

  // The session's own model when nothing was trained here.
  if (!outcome_ || !outcome_->result) {
    const auto current = model_.model();
    if (current) {
      ImGui::TextWrapped(
          "session model: %s, trained on %s", current->method.c_str(),
          current->provenance.value("training_files", nlohmann::json::array()).dump().c_str());
      const auto threshold = model_.errpThreshold();
      if (current->errp) {
        std::string channels;
        for (const auto& c : current->errp->pipeline.channels)
          channels += (channels.empty() ? "" : ", ") + c;
        ImGui::TextWrapped(
            "ErrP classifier: %s on %s, %.0f-%.0f Hz, %.0f-%.0f ms after the feedback; "
            "cross-validated AUC %.3f; a selection is rejected above a posterior of error of "
            "%.2f",
            current->errp->method.c_str(), channels.c_str(),
            current->errp->pipeline.filter.highpass_hz, current->errp->pipeline.filter.lowpass_hz,
            1000.0 * current->errp->pipeline.window.start_s,
            1000.0 * current->errp->pipeline.window.end_s, current->errp_auc,
            threshold.value_or(0.5));
      } else if (threshold) {
        ImGui::TextDisabled(
            "ErrP classifier: none yet (trained after the calibration run's "
            "feedback block); until then selections are executed unchecked");
      }
    } else {
      ImGui::TextDisabled("no model yet: the session trains one after its calibration run");
    }
    // How well it did on the calibration run, cross-validated, before any online selection.
    if (const auto calibration = model_.sessionCalibration()) {
      heading("the session's calibration run, cross-validated (before going online)");
      drawEvaluation(*calibration);
    }
    drawSessionErps();
    return;
  }
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
      model_.useModel(r.model);
      message_ = "the session now uses this model";
    } catch (const std::exception& error) {
      message_ = error.what();
    }
  }
}

PanelRegistry::Entry trainingPanel() {
  return {"training",
          "train a classifier on recordings; the ERPs, AUC and accuracy by sequences",
          {[](const PanelContext& c) { return std::make_unique<TrainingPanel>(c.model); }, false}};
}

}  // namespace arbci::ui
