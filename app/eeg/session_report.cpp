#include "eeg/session_report.h"

#include <fstream>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "arbci/bci/p300_dataset.h"
#include "arbci/bci/p300_model.h"
#include "arbci/bci/selection_marks.h"
#include "arbci/session/trust_report.h"
#include "eeg/p300_plots.h"

namespace arbci::app {
namespace {

std::string escaped(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '&':
        out += "&amp;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// The calibration run's ERP and cross-validated accuracy by sequences, made again from the
// folder's recording with the session's model's pipeline and method. "" when written, else why
// not.
std::string calibrationFigures(const std::filesystem::path& folder,
                               const std::filesystem::path& out) {
  if (!std::filesystem::exists(folder / "model.json")) return "no model.json (no model trained)";
  if (!std::filesystem::exists(folder / "recording.bdf")) return "no recording.bdf";
  try {
    const bci::P300Model model = bci::P300Model::load(folder / "model.json");
    const bci::Recording recording = bci::readRecording(folder / "recording.bdf");
    const auto marks = bci::markedSelections(recording);
    const bci::SelectionsOfKind calibration =
        bci::selectionsOfKind(recording, marks, {bci::SelectionKind::Calibration});
    if (calibration.selections.size() < 2) return "fewer than two calibration selections";
    bci::DatasetOptions options;
    for (const auto& m : calibration.selections) options.selection_starts.push_back(m.sample);
    const bci::P300Dataset data =
        bci::buildDataset({calibration.recording}, model.pipeline, {}, options);
    bci::TrainingSettings training;
    training.method = model.method;
    const bci::TrainingResult result = bci::trainModel(data, model.pipeline, training);
    writeP300Plots(out, data, result.cross_validation.report,
                   "calibration run (" + model.method + ", cross-validated)");
    return "";
  } catch (const std::exception& error) {
    return error.what();
  }
}

}  // namespace

std::filesystem::path writeSessionReport(const std::filesystem::path& folder) {
  std::ifstream in(folder / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(in, nullptr, false);
  if (!summary.is_object())
    throw std::runtime_error((folder / "summary.json").string() + ": no summary to report on");
  std::ostringstream html;
  const nlohmann::json& labels = summary.value("labels", nlohmann::json::object());
  html << "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>ARBCI session "
       << escaped(folder.filename().string()) << "</title>\n"
       << "<style>body{font-family:sans-serif;max-width:60em;margin:2em auto}td{padding:2px 8px;"
          "vertical-align:top}tr.caution td:first-child{color:#b35900;font-weight:bold}"
          "img{max-width:100%}</style></head><body>\n";
  html << "<h1>Session " << escaped(folder.filename().string()) << "</h1>\n<p>subject "
       << escaped(labels.value("subject", "")) << ", session "
       << escaped(labels.value("session", "")) << ", task " << escaped(labels.value("task", ""))
       << ", run " << escaped(labels.value("run", ""))
       << "; ended: " << escaped(summary.value("ended", "")) << " ("
       << escaped(summary.value("end_reason", "")) << ") after " << summary.value("duration_s", 0.0)
       << " s</p>\n";
  const std::vector<session::TrustRow> rows = session::trustRows(summary);
  int cautions = 0;
  for (const auto& row : rows) cautions += row.caution;
  html << "<h2>Can the data be trusted?</h2>\n<p>"
       << (cautions ? std::to_string(cautions) +
                          " reason(s) to look again before using this run's data (marked !)"
                    : std::string("nothing in this run's record calls for caution"))
       << "</p>\n<table>\n";
  for (const auto& row : rows) {
    html << "<tr" << (row.caution ? " class=\"caution\"" : "") << "><td>"
         << (row.caution ? "! " : "") << escaped(row.what) << "</td><td>" << escaped(row.text)
         << "</td></tr>\n";
  }
  html << "</table>\n<h2>Trials</h2>\n<table>\n";
  for (const nlohmann::json& t : summary.value("trials", nlohmann::json::array())) {
    html << "<tr><td>trial " << t.value("trial", 0) << "</td><td>object "
         << t.value("selected_object", nlohmann::json()).dump() << " (intended "
         << t.value("intended_object", nlohmann::json()).dump() << "), cell "
         << t.value("selected_cell", nlohmann::json()).dump() << " (intended "
         << t.value("intended_cell", nlohmann::json()).dump()
         << "): " << escaped(t.value("outcome", "")) << "</td></tr>\n";
  }
  html << "</table>\n<h2>Calibration run</h2>\n";
  const std::filesystem::path figures = folder / "report";
  const std::string missing = calibrationFigures(folder, figures);
  if (missing.empty()) {
    html << "<p>The ERP at each channel (target and non-target, the difference), where in time "
            "and on the scalp the classes differ (signed r&sup2;; the difference at its peak), "
            "and the accuracy by sequences, cross-validated by selection, made again from "
            "recording.bdf with the model's pipeline (the figures summary.json gives are the "
            "session's own; the filter's start on the recording's first sample can move them a "
            "little); the numbers in report/erp.json.</p>\n"
            "<img src=\"report/erp.png\" alt=\"ERP\">\n"
            "<img src=\"report/r2.png\" alt=\"signed r-squared by channel and time\">\n"
            "<img src=\"report/scalp.png\" alt=\"the difference on the scalp at its peak\">\n"
            "<img src=\"report/accuracy.png\" alt=\"accuracy by sequences\">\n";
  } else {
    html << "<p>No figures: " << escaped(missing) << ".</p>\n";
  }
  html << "<p>Everything here comes from summary.json, log.jsonl, model.json and recording.bdf "
          "in this folder.</p>\n</body></html>\n";
  const std::filesystem::path path = folder / "report.html";
  std::ofstream out(path);
  out << html.str();
  if (!out) throw std::runtime_error(path.string() + ": cannot be written");
  return path;
}

}  // namespace arbci::app
