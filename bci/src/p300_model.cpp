#include "arbci/bci/p300_model.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

namespace arbci::bci {

void P300Model::checkCompatible(const SignalInfo& info, const std::string& what) const {
  if (std::abs(info.rate_hz - rate_hz) > 1e-6) {
    throw ModelError(what + " is sampled at " + std::to_string(info.rate_hz) +
                     " Hz; the model was trained at " + std::to_string(rate_hz) + " Hz");
  }
  for (const std::string& channel : pipeline.channels) {
    if (std::find(info.channels.begin(), info.channels.end(), channel) == info.channels.end()) {
      throw ModelError(what + " has no channel " + channel + ", which the model uses");
    }
  }
}

nlohmann::json P300Model::toJson() const {
  nlohmann::json json;
  json["format"] = "arbci-p300-model";
  json["version"] = 1;
  json["method"] = method;
  json["signal"] = {{"rate_hz", rate_hz}};
  const FilterSettings& f = pipeline.filter;
  json["pipeline"] = {{"filter",
                       {{"common_average", f.common_average},
                        {"highpass_hz", f.highpass_hz},
                        {"lowpass_hz", f.lowpass_hz},
                        {"order", f.order},
                        {"notch_hz", f.notch_hz},
                        {"notch_q", f.notch_q}}},
                      {"window_s", {pipeline.window.start_s, pipeline.window.end_s}},
                      {"decimate_hz", pipeline.decimate_hz},
                      {"decimation_factor", pipeline.decimationFactor(rate_hz)},
                      {"channels", pipeline.channels},
                      {"zero_phase", pipeline.zero_phase}};
  json["shape"] = {{"channels", shape.channels}, {"bins", shape.bins}};
  json["classifier"] = classifier->toJson();
  json["score_model"] = {{"target_mean", score_model.target_mean},
                         {"other_mean", score_model.other_mean},
                         {"sd", score_model.sd}};
  if (!std::isnan(score_model.median)) json["score_model"]["median"] = score_model.median;
  json["score_model"]["rho"] = score_model.rho;
  json["paradigm"] = {
      {"kind", layout.kind == ParadigmLayout::Kind::RowColumn ? "row/column" : "single stimulus"},
      {"stimuli", layout.stimuli},
      {"rows", layout.rows},
      {"columns", layout.columns},
      {"soa_s", layout.soa_s},
      {"symbols", layout.symbols}};
  json["provenance"] = provenance;
  if (errp) {
    json["errp"] = errp->toJson();
    if (!std::isnan(errp_auc)) json["errp"]["cross_validated_auc"] = errp_auc;
  }
  return json;
}

P300Model P300Model::fromJson(const nlohmann::json& json, const std::string& source) {
  try {
    if (json.value("format", "") != "arbci-p300-model")
      throw ModelError(source + ": not an ARBCI P300 model (format)");
    if (json.value("version", 0) != 1)
      throw ModelError(source + ": model version " +
                       json.value("version", nlohmann::json()).dump() + " is not 1");
    P300Model model;
    model.method = json.at("method").get<std::string>();
    model.rate_hz = json.at("signal").at("rate_hz").get<double>();
    if (!(model.rate_hz > 0.0)) throw ModelError(source + ": signal.rate_hz must be positive");
    const auto& p = json.at("pipeline");
    const auto& f = p.at("filter");
    FilterSettings& filter = model.pipeline.filter;
    filter.common_average = f.at("common_average").get<bool>();
    filter.highpass_hz = f.at("highpass_hz").get<double>();
    filter.lowpass_hz = f.at("lowpass_hz").get<double>();
    filter.order = f.at("order").get<int>();
    filter.notch_hz = f.at("notch_hz").get<double>();
    filter.notch_q = f.at("notch_q").get<double>();
    const auto window = p.at("window_s").get<std::vector<double>>();
    if (window.size() != 2 || !(window[1] > window[0]))
      throw ModelError(source + ": pipeline.window_s must be [start, end]");
    model.pipeline.window = {window[0], window[1]};
    model.pipeline.decimate_hz = p.at("decimate_hz").get<double>();
    model.pipeline.channels = p.at("channels").get<std::vector<std::string>>();
    model.pipeline.zero_phase = p.value("zero_phase", false);
    model.shape = {json.at("shape").at("channels").get<int>(),
                   json.at("shape").at("bins").get<int>()};
    if (model.shape.channels != static_cast<int>(model.pipeline.channels.size())) {
      throw ModelError(source + ": shape.channels does not match pipeline.channels");
    }
    model.classifier = classifierFromJson(json.at("classifier"), model.shape);
    const auto& s = json.at("score_model");
    model.score_model = {s.at("target_mean").get<double>(), s.at("other_mean").get<double>(),
                         s.at("sd").get<double>(),
                         s.contains("median") ? s.at("median").get<double>()
                                              : std::numeric_limits<double>::quiet_NaN()};
    // A model from before the correlation was kept: its flashes counted as independent.
    model.score_model.rho = std::clamp(s.value("rho", 0.0), 0.0, 0.5);
    const auto& l = json.at("paradigm");
    if (l.at("kind").get<std::string>() == "row/column") {
      model.layout = ParadigmLayout::matrix(l.at("rows").get<int>(), l.at("columns").get<int>(),
                                            l.at("soa_s").get<double>());
    } else {
      model.layout =
          ParadigmLayout::single(l.at("stimuli").get<int>(), l.at("soa_s").get<double>());
    }
    model.layout.symbols = l.value("symbols", std::vector<std::string>{});
    model.provenance = json.value("provenance", nlohmann::json::object());
    if (json.contains("errp")) {
      model.errp = std::make_shared<const P300Model>(fromJson(json.at("errp"), source + " (errp)"));
      model.errp_auc =
          json.at("errp").value("cross_validated_auc", std::numeric_limits<double>::quiet_NaN());
    }
    return model;
  } catch (const nlohmann::json::exception& error) {
    throw ModelError(source + ": " + error.what());
  } catch (const std::invalid_argument& error) {
    throw ModelError(source + ": " + error.what());
  }
}

void P300Model::save(const std::filesystem::path& path) const {
  std::ofstream out(path);
  if (!out) throw ModelError(path.string() + ": cannot write");
  out << toJson().dump(2) << "\n";
  out.close();
  if (!out) throw ModelError(path.string() + ": writing failed");
}

P300Model P300Model::load(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw ModelError(path.string() + ": cannot open");
  nlohmann::json json;
  try {
    in >> json;
  } catch (const nlohmann::json::exception& error) {
    throw ModelError(path.string() + ": not JSON (" + error.what() + ")");
  }
  return fromJson(json, path.string());
}

std::string P300Model::bci2000Fragment() const {
  if (std::abs(pipeline.window.start_s) > 1e-9) {
    throw ModelError(
        "BCI2000's P3TemporalFilter epochs start at the stimulus; this model's window starts at " +
        std::to_string(pipeline.window.start_s) + " s");
  }
  const int factor = pipeline.decimationFactor(rate_hz);
  const Eigen::VectorXd w = classifier->weights();
  if (w.size() != shape.size()) {
    throw ModelError("a " + method +
                     " model is not linear in its features: BCI2000's LinearClassifier cannot "
                     "run it (train a linear method for BCI2000)");
  }
  std::ostringstream entries;
  int count = 0;
  for (int c = 0; c < shape.channels; ++c) {
    for (int b = 0; b < shape.bins; ++b) {
      const double weight = w[c * shape.bins + b];
      if (weight == 0.0) continue;
      // Decimation by moving average is the same weight on each sample of the bin, divided.
      for (int s = b * factor; s < (b + 1) * factor; ++s) {
        entries << " " << c + 1 << " " << s + 1 << " 1 " << weight / factor;
        ++count;
      }
    }
  }
  std::ostringstream out;
  out << "Filtering:LinearClassifier matrix Classifier= " << count
      << " { input%20channel input%20element%20(bin) output%20channel weight }" << entries.str()
      << " // ARBCI " << method << " model\n";
  out << "Filtering:P3TemporalFilter int EpochLength= "
      << std::lround(pipeline.window.end_s * 1000.0)
      << "ms 500ms 0 % // Length of data epoch from stimulus onset\n";
  out << "Filtering:P3TemporalFilter int EpochsToAverage= 1 1 0 % // Number of epochs to average\n";
  out << "Source:Online%20Processing:TransmissionFilter list TransmitChList= "
      << pipeline.channels.size();
  for (const std::string& c : pipeline.channels) out << " " << c;
  out << " // channels the classifier reads, in its input-channel order\n";
  out << "Filtering:SpatialFilter int SpatialFilterType= "
      << (pipeline.filter.common_average ? 3 : 0) << " 2 0 3 // "
      << (pipeline.filter.common_average ? "common average reference" : "none")
      << " (enumeration)\n";
  const FilterSettings& f = pipeline.filter;
  out << "Filtering:IIRBandpass float HighPassCorner= " << f.highpass_hz
      << "Hz 0.1Hz % % // ARBCI's Butterworth high-pass\n";
  out << "Filtering:IIRBandpass float LowPassCorner= " << f.lowpass_hz
      << "Hz 0Hz % % // ARBCI's Butterworth low-pass\n";
  out << "Filtering:IIRBandpass int FilterOrder= " << f.order
      << " 4 1 % // of each Butterworth half\n";
  out << "Filtering:IIRBandpass float NotchCenter= " << f.notch_hz << "Hz 0Hz % % // 0: none\n";
  return out.str();
}

TrainingResult trainModel(const P300Dataset& data, const PipelineSettings& pipeline,
                          const TrainingSettings& settings, const Progress& progress) {
  TrainingResult result;
  result.cross_validation = crossValidate(data, settings, progress);
  // The final model learns from every labelled epoch.
  std::vector<int> rows;
  for (const SelectionEpochs& s : data.selections) {
    if (!s.target_codes.empty()) rows.insert(rows.end(), s.epochs.begin(), s.epochs.end());
  }
  Eigen::MatrixXd x(static_cast<Eigen::Index>(rows.size()), data.features.cols());
  std::vector<bool> y;
  for (size_t i = 0; i < rows.size(); ++i) {
    x.row(static_cast<Eigen::Index>(i)) = data.features.row(rows[i]);
    y.push_back(data.target[static_cast<size_t>(rows[i])]);
  }
  auto classifier = makeClassifier(settings);
  classifier->train(x, y, data.shape,
                    progress ? Progress([&](double f, const std::string& stage) {
                      const double folds = result.cross_validation.folds;
                      progress((folds + f) / (folds + 1.0), "final model: " + stage);
                    })
                             : Progress());
  P300Model& model = result.model;
  model.method = settings.method;
  model.rate_hz = data.info.rate_hz;
  model.pipeline = withMethodRate(pipeline, settings.method);
  model.pipeline.channels = data.feature_channels;
  model.shape = data.shape;
  model.classifier = std::move(classifier);
  model.score_model = result.cross_validation.score_model;
  model.layout = data.layout;
  const EvaluationReport& report = result.cross_validation.report;
  model.provenance = {{"training_files", data.sources},
                      {"epochs", rows.size()},
                      {"selections", report.selections_with_truth},
                      {"cross_validation",
                       {{"folds", result.cross_validation.folds},
                        {"split", "by selection"},
                        {"auc", report.auc},
                        {"accuracy_by_sequences", report.accuracy},
                        {"bits_per_minute", report.bits_per_minute}}}};
  const ClassifierParts& parts = classifiers().at(settings.method).make;
  if (parts.parameters)
    model.provenance["parameters"] = parts.parameters(withMethodDefaults(settings));
  return result;
}

}  // namespace arbci::bci
