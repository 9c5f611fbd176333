#include "arbci/bci/settings.h"

#include "arbci/bci/classifier.h"

namespace arbci::bci {

using core::Key;
using core::Type;
using Json = nlohmann::json;

const core::Schema<ParadigmSettings>& paradigmSchema() {
  static const core::Schema<ParadigmSettings> table = [] {
    core::Schema<ParadigmSettings> t("paradigm",
                                     "The P300 paradigm: flashes, sequences, dynamic "
                                     "stopping, the calibration run and the trials");
    using P = ParadigmSettings;
    t.number("display_hz", &P::display_hz, 60.0, 10.0, 500.0,
             "the HMD's frame rate: flashes last whole frames of it", "Hz")
        .number("flash_ms", &P::flash_ms, 60.0, 5.0, 2000.0,
                "how long a stimulus is lit (rounded to whole frames)", "ms")
        .number("isi_ms", &P::isi_ms, 120.0, 0.0, 5000.0,
                "the dark gap after a flash before the next onset (rounded to whole frames)", "ms")
        .integer("sequences", &P::sequences, 8, 1, 100,
                 "sequences of an online selection (every stimulus once each), the most with "
                 "dynamic stopping")
        .integer("min_sequences", &P::min_sequences, 3, 1, 100,
                 "dynamic stopping never decides before this many sequences")
        .number("certainty", &P::certainty, 0.999, 0.0, 1.0,
                "dynamic stopping: decide once the choice is this probable (0: always all "
                "sequences); calibration none: the arm acts only on an object selection at "
                "least this probable")
        .number("act_certainty", &P::act_certainty, 0.9, 0.0, 1.0,
                "the arm acts only on a selection at least this probable: an object below it "
                "is not grasped (its trial ends), a cell below it not put down on (the object "
                "goes back); what ran out of sequences below it is said, not acted on (0: act "
                "on every selection; calibration none: paradigm.certainty)")
        .integer("calibration_selections", &P::calibration_selections, 8, 2, 200,
                 "cued selections of the calibration run")
        .integer("calibration_sequences", &P::calibration_sequences, 8, 1, 100,
                 "sequences of each calibration selection (always all)")
        .integer("trials", &P::trials, 3, 1, 1000,
                 "online trials (select an object, grasp, select a cell, put down)")
        .text("calibration", &P::calibration, "cued",
              "cued: a calibration run trains the classifier first (unless a model is given); "
              "none: the trials start at once and the classifier learns from them without "
              "labels, the arm held until the model is trusted",
              [] {
                return std::vector<std::string>{"cued", "none"};
              })
        .integer("learning_min_selections", &P::learning_min_selections, 5, 2, 100,
                 "calibration none: the arm moves only once the model has learnt from this many "
                 "object selections")
        .integer("learning_sequences", &P::learning_sequences, 0, 0, 100,
                 "calibration none: until the model is trusted, an object selection flashes this "
                 "many sequences, all of them: nothing is acted on, so its time goes to evidence "
                 "for the fit (0: as many as learning_max_sequences allows)")
        .integer("learning_max_sequences", &P::learning_max_sequences, 0, 0, 100,
                 "calibration none: once the model is trusted, an object selection flashes until "
                 "as certain as paradigm.certainty asks (the arm acts on nothing less), up to "
                 "this many sequences (0: twice sequences)")
        .number("learning_min_consistency", &P::learning_min_consistency, 0.8, 0.0, 1.0,
                "calibration none: ... and once a model learnt from the other selections "
                "decodes at least this share of them as the fit does (held out; chance is one "
                "over the objects)")
        .boolean("adapt", &P::adapt, false,
                 "a calibrated session goes on learning from its object selections (the "
                 "calibration run's labels kept, the rest's found by EM)")
        .number("cue_s", &P::cue_s, 1.5, 0.0, 60.0,
                "calibration: the target is shown this long before its flashes", "s")
        .number("result_s", &P::result_s, 1.0, 0.0, 60.0, "a selection is shown this long", "s")
        .number("pause_s", &P::pause_s, 1.0, 0.0, 60.0, "the pause between selections", "s")
        .number("no_view_pause_s", &P::no_view_pause_s, 10.0, 1.0, 600.0,
                "a selection whose every flash is withheld this long (its objects or the "
                "reference marker out of view) pauses the session with that reason and resumes "
                "when they are seen again; headless, the run ends",
                "s")
        .boolean("errp", &P::errp, false,
                 "error-related potentials: train an ErrP classifier and correct the selections "
                 "it rejects")
        .integer("errp_calibration_feedbacks", &P::errp_calibration_feedbacks, 100, 4, 1000,
                 "cued feedbacks closing the calibration run (the ErrP classifier's data)")
        .number("errp_wrong_rate", &P::errp_wrong_rate, 0.25, 0.05, 0.5,
                "the fraction of those feedbacks deliberately wrong")
        .number("errp_runner_up", &P::errp_runner_up, 0.5, 0.0, 1.0,
                "a rejected selection is replaced by the runner-up when it holds at least this "
                "share of the rest's probability")
        .integer("errp_repeat_sequences", &P::errp_repeat_sequences, 0, 0, 100,
                 "else the selection is made again with this many sequences (0: twice "
                 "`sequences`)")
        .integer("errp_max_corrections", &P::errp_max_corrections, 2, 0, 10,
                 "after this many rejections the trial is skipped");
    t.rule([](const Json& p) -> std::optional<std::pair<std::string, std::string>> {
      if (p["min_sequences"].get<int>() > p["sequences"].get<int>())
        return std::pair{"min_sequences", "= " + p["min_sequences"].dump() + " must lie in [1, " +
                                              p["sequences"].dump() + "] (at most `sequences`)"};
      return std::nullopt;
    });
    return t;
  }();
  return table;
}

ParadigmSettings::ParadigmSettings() {
  paradigmSchema().applyDefaults(*this);
}

const core::Schema<FilterSettings>& filterSchema() {
  static const core::Schema<FilterSettings> table = [] {
    core::Schema<FilterSettings> t("filters",
                                   "Common average, Butterworth band-pass and notch, in order");
    using F = FilterSettings;
    t.boolean("common_average", &F::common_average, false,
              "subtract the mean over channels from every sample first")
        .number("highpass_hz", &F::highpass_hz, 0.5, 0.0, 100.0,
                "Butterworth high-pass edge (0: none)", "Hz")
        .number("lowpass_hz", &F::lowpass_hz, 20.0, 0.0, 500.0,
                "Butterworth low-pass edge (0: none)", "Hz")
        .integer("filter_order", &F::order, 4, 1, 12, "the order of each Butterworth half")
        .number("notch_hz", &F::notch_hz, 50.0, 0.0, 500.0,
                "the power line's frequency to notch out (0: none; 60 in the Americas)", "Hz")
        .number("notch_q", &F::notch_q, 25.0, 1.0, 200.0,
                "the notch's quality (bandwidth = frequency / q)");
    return t;
  }();
  return table;
}

FilterSettings::FilterSettings() {
  filterSchema().applyDefaults(*this);
}

const core::Schema<PipelineSettings>& pipelineSchema() {
  static const core::Schema<PipelineSettings> table = [] {
    core::Schema<PipelineSettings> t(
        "pipeline", "Between the signal and the classifier: filters, window, decimation");
    using P = PipelineSettings;
    t.merge(filterSchema(), &P::filter);
    Key window{"window_ms", Type::Numbers, Json::array({0, 800}),
               "the epoch after each stimulus that the features are taken from", "ms"};
    window.min_items = window.max_items = 2;
    window.low = -2000.0;
    window.high = 5000.0;
    t.custom(
         window,
         [](P& p, const Json& j) {
           p.window = {j[0].get<double>() / 1000.0, j[1].get<double>() / 1000.0};
         },
         [](const P& p) {
           return Json::array({p.window.start_s * 1000.0, p.window.end_s * 1000.0});
         })
        .number("decimate_hz", &P::decimate_hz, 0.0, 0.0, 500.0,
                "the features' rate: the epoch is averaged in bins to it (0: the method's own, " +
                    std::to_string(static_cast<int>(ClassifierParts{}.feature_rate_hz)) +
                    " Hz as BCI2000 for most; arbci train --method's help and docs/settings.md's "
                    "classifiers "
                    "give each method's own)",
                "Hz")
        .texts("channels", &P::channels, {}, 0, "the feature channels ([]: every EEG channel)")
        .boolean("zero_phase", &P::zero_phase, false,
                 "offline only: filter forward and backward (no phase lag; never online)");
    t.rule([](const Json& p) -> std::optional<std::pair<std::string, std::string>> {
      if (!(p["window_ms"][1].get<double>() > p["window_ms"][0].get<double>()))
        return std::pair{"window_ms", "= " + p["window_ms"].dump() + " must end after it starts"};
      return std::nullopt;
    });
    return t;
  }();
  return table;
}

PipelineSettings::PipelineSettings() {
  pipelineSchema().applyDefaults(*this);
}

const core::Schema<TrainingSettings>& trainingSchema() {
  static const core::Schema<TrainingSettings> table = [] {
    core::Schema<TrainingSettings> t("training", "How a classifier is trained and cross-validated");
    using T = TrainingSettings;
    t.text("method", &T::method, "slda", "the classifier (docs/settings.md's classifiers)",
           [] { return classifiers().names(); })
        .number("shift_ms", &T::shift_ms, 94.0, 0.0, 400.0,
                "shift-lda: the largest latency shift tried, each way (the response's latency "
                "spread)",
                "ms")
        .integer("folds", &T::folds, 10, 2, 100,
                 "cross-validation folds (at most one per selection or file)")
        .text("folds_by", &T::folds_by, "",
              "selection, block or file (\"\": by selection, or by block when the codes are "
              "classes)",
              [] {
                return std::vector<std::string>{"", "selection", "block", "file"};
              });
    Key p_enter{"p_enter", Type::Number, 0.10, "SWLDA: a feature enters below this p-value",
                "",        0.0,          1.0};
    Key p_remove{"p_remove", Type::Number,
                 0.15,       "SWLDA: a feature leaves above this p-value (more than p_enter)",
                 "",         0.0,
                 1.0};
    Key max_features{"max_features", Type::Integer, 60, "SWLDA: most features kept", "", 1, 1000};
    Key filters{"xdawn_filters",
                Type::Integer,
                0,
                "xDAWN spatial filters kept (riemann: per class; 0: the method's own, which arbci "
                "train --method's help and docs/settings.md's classifiers give)",
                "",
                0,
                64};
    t.custom(
         p_enter, [](T& s, const Json& j) { s.swlda.p_enter = j.get<double>(); },
         [](const T& s) { return Json(s.swlda.p_enter); })
        .custom(
            p_remove, [](T& s, const Json& j) { s.swlda.p_remove = j.get<double>(); },
            [](const T& s) { return Json(s.swlda.p_remove); })
        .custom(
            max_features, [](T& s, const Json& j) { s.swlda.max_features = j.get<int>(); },
            [](const T& s) { return Json(s.swlda.max_features); })
        .custom(
            filters, [](T& s, const Json& j) { s.xdawn.filters = j.get<int>(); },
            [](const T& s) { return Json(s.xdawn.filters); });
    t.rule([](const Json& s) -> std::optional<std::pair<std::string, std::string>> {
      if (!(s["p_remove"].get<double>() > s["p_enter"].get<double>()))
        return std::pair{"p_remove", "= " + s["p_remove"].dump() + " must exceed p_enter " +
                                         s["p_enter"].dump() +
                                         " (or a feature could enter and leave forever)"};
      return std::nullopt;
    });
    return t;
  }();
  return table;
}

TrainingSettings::TrainingSettings() {
  trainingSchema().applyDefaults(*this);
}

const core::Schema<SimulatedSubjectConfig>& subjectSchema() {
  static const core::Schema<SimulatedSubjectConfig> table = [] {
    core::Schema<SimulatedSubjectConfig> t("subject", "The EEG signal's shape");
    using S = SimulatedSubjectConfig;
    Key seed{"seed", Type::Integer,
             1,      "the simulated subject's (and world's, and flash order's) random seed",
             "",     0,
             1 << 30};
    t.custom(
         seed, [](S& s, const Json& j) { s.seed = j.get<std::uint64_t>(); },
         [](const S& s) { return Json(s.seed); })
        .texts("montage", &S::montage, {"Fz", "Cz", "P3", "Pz", "P4", "PO7", "Oz", "PO8"}, 1,
               "the EEG channels' names (10-20); a live source's must include the model's")
        .number("rate_hz", &S::rate_hz, 256.0, 64.0, 4096.0, "the sampling rate", "Hz")
        .integer("block_size", &S::block_size, kBlockSize, 1, 4096,
                 "samples per block the source delivers (15 at 256 Hz: one 58.6 ms cycle)")
        .number("line_hz", &S::line_hz, 50.0, 0.0, 70.0, "the power line's frequency (0: none)",
                "Hz")
        .text("photodiode_channel", &S::photodiode_channel, "Photodiode",
              "the channel a photodiode on the HMD's patch feeds (simulated: a virtual one is "
              "added; \"\": none)");
    return t;
  }();
  return table;
}

SimulatedSubjectConfig::SimulatedSubjectConfig() {
  subjectSchema().applyDefaults(*this);
}

const core::Schema<LslSourceSettings>& lslSourceSchema() {
  static const core::Schema<LslSourceSettings> table = [] {
    core::Schema<LslSourceSettings> t("lsl",
                                      "A Lab Streaming Layer EEG stream (eeg.source \"lsl\")");
    using L = LslSourceSettings;
    t.text("name", &L::name, "", "the stream's name (\"\": any of the type)")
        .text("type", &L::type, "EEG", "the stream's type (\"\": any of the name)")
        .text("source_id", &L::source_id, "",
              "the stream's source id (\"\": any): picks one of several streams of the same "
              "name (`arbci eeg streams` lists them)")
        .text("host", &L::host, "",
              "the host the stream comes from, as `arbci eeg streams` shows it (\"\": any)")
        .number("resolve_timeout_s", &L::resolve_timeout_s, 5.0, 0.1, 600.0,
                "how long to look for the stream (and wait for its first sample)", "s");
    t.rule([](const Json& l) -> std::optional<std::pair<std::string, std::string>> {
      if (l["name"].get<std::string>().empty() && l["type"].get<std::string>().empty())
        return std::pair{"name", "or type is required to find a stream"};
      return std::nullopt;
    });
    return t;
  }();
  return table;
}

LslSourceSettings::LslSourceSettings() {
  lslSourceSchema().applyDefaults(*this);
}

const core::Schema<EegdevSourceSettings>& eegdevSourceSchema() {
  static const core::Schema<EegdevSourceSettings> table = [] {
    core::Schema<EegdevSourceSettings> t("eegdev",
                                         "An amplifier through eegdev (eeg.source \"eegdev\")");
    t.text("device", &EegdevSourceSettings::device, "",
           "eegdev's device string: device|option|value..., e.g. \"biosemi\", "
           "\"datafile|path|/data/s01.bdf\"");
    return t;
  }();
  return table;
}

EegdevSourceSettings::EegdevSourceSettings() {
  eegdevSourceSchema().applyDefaults(*this);
}

}  // namespace arbci::bci
