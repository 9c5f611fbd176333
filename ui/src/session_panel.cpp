// The Session panel: the paradigm's phase, start/pause/resume/abort, the subject and run before
// Start, the pre-flight check, tracking health, the cycle's timing per stage against the block
// budget, and the selections made.
#include <imgui.h>

#include <algorithm>
#include <cstdio>
#include <string>

#include "arbci/session/experimenter.h"
#include "arbci/session/record_text.h"
#include "arbci/ui/panel_registry.h"
#include "widgets.h"

namespace arbci::ui {
namespace {

using session::Action;

// participants.tsv's levels (BIDS): the code written, the label shown; the first is "not given".
struct Level {
  const char* code;
  const char* label;
};
constexpr Level kSexes[] = {
    {"", "sex: n/a"}, {"F", "F (female)"}, {"M", "M (male)"}, {"O", "O (other)"}};
constexpr Level kHands[] = {
    {"", "hand: n/a"}, {"R", "R (right)"}, {"L", "L (left)"}, {"A", "A (ambidextrous)"}};
template <size_t N>
int levelIndex(const Level (&levels)[N], const std::string& code) {
  for (size_t i = 0; i < N; ++i)
    if (code == levels[i].code) return static_cast<int>(i);
  return 0;
}

std::string seconds(double s) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f s", s);
  return text;
}

class SessionPanel final : public Panel {
 public:
  const char* title() const override { return "Session"; }
  void draw(const PanelInput& in) override;

 private:
  void buttons(const PanelInput& in);
  // Before Start: subject, session, task and run, and where the run will be written.
  void runLabels(const PanelInput& in);
  // "tracking lost" for the reference marker and each object seen too long ago.
  void trackingHealth(const PanelInput& in);
  void timing(const PanelInput& in);
  void notes(const PanelInput& in);
  bool labels_read_ = false;
  char note_[256] = "";
  char subject_[64] = "", visit_[64] = "", task_[64] = "", run_[16] = "";
  char age_[8] = "";
  int sex_ = 0, handedness_ = 0;  // indices into kSexes, kHands (0: not given)
};

void SessionPanel::draw(const PanelInput& in) {
  const session::CycleRecord& r = in.record;
  const bool started = r.paradigm.phase != bci::Phase::Setup;
  // One line (a narrow panel cuts it; the reason below wraps): the buttons stay where they are.
  ImGui::Text("%s", session::phaseText(r).c_str());
  // The calibration run counts its own selections (the trials come after it).
  if (const auto& c = r.paradigm.calibration_selection) {
    std::string counts;
    if (r.paradigm.calibration_retakes > 0)
      counts += ", " + std::to_string(r.paradigm.calibration_retakes) + " retaken";
    if (r.paradigm.reflashed_sequences > 0)
      counts += ", " + std::to_string(r.paradigm.reflashed_sequences) + " sequences shown again";
    ImGui::Text("calibration selection %d of %d%s, sequence %d, session time %.1f s", c->first,
                c->second, counts.c_str(), r.paradigm.sequence, r.time_s);
  } else {
    ImGui::Text("trial %d of %d, sequence %d, session time %.1f s", r.paradigm.trial,
                in.settings.paradigm.trials, r.paradigm.sequence, r.time_s);
  }
  buttons(in);
  // Learning from use: how far the model is, and while the arm is held, what it waits for.
  if (const auto& learning = r.p300.learning; learning && started) {
    const ImVec4 colour =
        learning->trusted ? ImVec4(0.5f, 0.9f, 0.5f, 1.0f) : ImVec4(1.0f, 0.8f, 0.35f, 1.0f);
    colouredWrapped(colour, learning->line());
  }
  // Why the session is not going as planned (a pause, a failed training, a refused grasp), or
  // how it ended: the same words as the operator log and the summary.
  if (const std::string why = session::reasonText(r); !why.empty())
    colouredWrapped(ImVec4(1.0f, 0.55f, 0.3f, 1.0f), why);
  if (!started && !r.ended) runLabels(in);
  // After an E-STOP or a robot fault: what each way on does, as long as the run waits for it.
  if (const std::string next = session::recoveryText(r); !next.empty())
    colouredWrapped(ImVec4(1.0f, 0.8f, 0.35f, 1.0f), next);
  if (r.robot.status && !r.robot.status->stop_reason.empty() && !r.ended) {
    colouredWrapped(
        ImVec4(1, 0.3f, 0.3f, 1),
        "robot stopped (" + r.robot.status->stop_reason +
            "): Resume here, or Retry step / Skip trial in the Robot panel, resets it and goes on "
            "(Home and Open gripper there first where the arm must be cleared).");
  }
  for (const std::string& line : r.preflight.lines) {
    const bool bad = line.find("FAILED") != std::string::npos || line.rfind("  ", 0) == 0;
    if (bad && !r.preflight.running) {
      colouredWrapped(ImVec4(1, 0.35f, 0.3f, 1), line);
    } else {
      ImGui::TextWrapped("%s", line.c_str());
    }
  }
  // The quality gate asked: the experimenter may start with the channels as they are (the log,
  // the recording and the summary say so).
  // So may the display's: run with every flash off limits annotated and no timing pauses.
  const bool quality = !r.preflight.questioned.empty(),
             display = !r.preflight.display_question.empty();
  if (quality && !started &&
      button(display ? "Start anyway, with these channels and this display"
                     : "Start anyway, with these channels",
             ""))
    in.requests.post(session::StartRequest{true, display});
  if (display && !quality && !started &&
      button("Run annotated on this display (no timing pauses this run)", ""))
    in.requests.post(session::StartRequest{false, true});
  notes(in);
  trackingHealth(in);
  timing(in);
  heading("selections");
  for (const std::string& line : session::selectionLines(r)) ImGui::TextUnformatted(line.c_str());
}

// A note the experimenter types goes into the recording at this moment ("Note: ..."), and into
// the log: what happened in the room belongs beside the EEG it explains.
void SessionPanel::notes(const PanelInput& in) {
  if (in.record.ended) return;
  ImGui::SetNextItemWidth(std::max(120.0f, ImGui::GetContentRegionAvail().x - 110.0f));
  const bool entered = ImGui::InputTextWithHint("##note", "a note for the recording", note_,
                                                sizeof note_, ImGuiInputTextFlags_EnterReturnsTrue);
  ImGui::SameLine();
  const bool empty = note_[0] == '\0';
  if ((button("Add note", empty ? "type the note first" : "") || entered) && !empty) {
    in.requests.post(session::NoteRequest{note_});
    note_[0] = '\0';
  }
}

void SessionPanel::buttons(const PanelInput& in) {
  // Every button in its own place whatever the state (disabled with its reason where it cannot
  // act): a double click never lands on a button that took another's place.
  const session::CycleRecord& r = in.record;
  const bool started = r.paradigm.phase != bci::Phase::Setup;
  const std::string& labels_problem = started ? std::string() : in.window.runTarget().problem;
  if (button("Start", !labels_problem.empty() ? labels_problem : whyNot(Action::Start, r)))
    in.requests.post(session::StartRequest{});
  ImGui::SameLine();
  if (button("Pause", whyNot(Action::Pause, r))) in.requests.post(session::PauseRequest{});
  ImGui::SameLine();
  if (button("Resume", whyNot(Action::Resume, r))) in.requests.post(session::ResumeRequest{});
  ImGui::SameLine();
  if (confirmedButton("Abort", whyNot(Action::Abort, r),
                      "Abort the session? It ends now; what was recorded is kept.", "Yes, abort"))
    in.requests.post(session::AbortRequest{});
  ImGui::SameLine();
  emergencyStopButton(in);
}

void SessionPanel::runLabels(const PanelInput& in) {
  heading("subject and run");
  if (!labels_read_) {
    const core::RunLabels& l = in.record.labels;
    std::snprintf(subject_, sizeof subject_, "%s", l.subject.c_str());
    std::snprintf(visit_, sizeof visit_, "%s", l.session.c_str());
    std::snprintf(task_, sizeof task_, "%s", l.task.c_str());
    std::snprintf(run_, sizeof run_, "%s", l.run.c_str());
    std::snprintf(age_, sizeof age_, "%s", l.age.c_str());
    sex_ = levelIndex(kSexes, l.sex);
    handedness_ = levelIndex(kHands, l.handedness);
    labels_read_ = true;
  }
  bool changed = false;
  const float width = std::max(60.0f, (ImGui::GetContentRegionAvail().x - 24.0f) / 4.0f);
  struct Field {
    const char* label;
    const char* hint;
    char* text;
    size_t size;
  };
  const Field fields[] = {{"subject", "subject (e.g. 07)", subject_, sizeof subject_},
                          {"session", "session (optional)", visit_, sizeof visit_},
                          {"task", "task", task_, sizeof task_},
                          {"run", "run: next free", run_, sizeof run_}};
  for (size_t i = 0; i < std::size(fields); ++i) {
    if (i > 0) ImGui::SameLine();
    ImGui::SetNextItemWidth(width);
    ImGui::PushID(fields[i].label);
    changed |= ImGui::InputTextWithHint("##label", fields[i].hint, fields[i].text, fields[i].size);
    ImGui::PopID();
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip("%s (BIDS entity: letters and digits)", fields[i].hint);
    recordField(fields[i].label, width);
  }
  // What participants.tsv says of the subject (BIDS; each may stay not given).
  ImGui::SetNextItemWidth(width);
  changed |= ImGui::InputTextWithHint("##age", "age (years)", age_, sizeof age_,
                                      ImGuiInputTextFlags_CharsDecimal);
  recordField("age", width);
  const auto level = [&](const char* id, const Level* levels, size_t count, int& chosen) {
    ImGui::SameLine();
    ImGui::SetNextItemWidth(width);
    const bool open = ImGui::BeginCombo(id, levels[chosen].label);
    recordCombo(std::string(id + 2), width, open);
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip("the subject's %s, for participants.tsv (BIDS)", id + 2);
    if (open) {
      for (size_t i = 0; i < count; ++i)
        if (ImGui::Selectable(levels[i].label, static_cast<int>(i) == chosen)) {
          chosen = static_cast<int>(i);
          changed = true;
        }
      ImGui::EndCombo();
    }
  };
  level("##sex", kSexes, std::size(kSexes), sex_);
  level("##handedness", kHands, std::size(kHands), handedness_);
  if (changed)
    in.requests.post(session::LabelsRequest{
        {subject_, visit_, task_, run_, age_, kSexes[sex_].code, kHands[handedness_].code}});
  const RunTarget& target = in.window.runTarget();
  if (!target.problem.empty()) {
    colouredWrapped(ImVec4(1.0f, 0.55f, 0.3f, 1.0f), target.problem);
  } else {
    ImGui::TextWrapped("%s", target.target.c_str());
  }
}

void SessionPanel::trackingHealth(const PanelInput& in) {
  heading("tracking");
  const session::CycleRecord& r = in.record;
  const double max_age = in.settings.tracker.max_pose_age_s;
  const ImVec4 lost(1.0f, 0.35f, 0.3f, 1.0f);
  const auto& world = r.tracking.world;
  const int reference_id = world ? world->reference().id : in.settings.world.reference_id;
  const std::optional<double> reference =
      world ? world->referenceAge(r.time_s) : std::optional<double>();
  if (!reference || *reference > max_age) {
    ImGui::TextColored(lost, "reference %d: tracking lost%s", reference_id,
                       reference ? (" (" + seconds(*reference) + ")").c_str() : " (never seen)");
  } else {
    ImGui::Text("reference %d: seen", reference_id);
  }
  const int held = r.robot.holding().value_or(-1);
  // Every object of the session, the ones the cameras never saw (or not since the robot moved
  // them) too: an empty table is named object by object.
  for (const session::WorldObjectSettings& object : in.settings.world.objects) {
    const int id = object.id;
    ImGui::SameLine(0.0f, 20.0f);
    if (ImGui::GetContentRegionAvail().x < 150.0f) ImGui::NewLine();
    const auto o = world ? world->object(id) : std::nullopt;
    if (id == held) {
      ImGui::Text("object %d: in the gripper", id);
    } else if (!o) {
      ImGui::TextColored(lost, "object %d: not seen", id);
    } else if (const double age = o->age(r.time_s); age > max_age) {
      ImGui::TextColored(lost, "object %d: lost (%s)", id, seconds(age).c_str());
    } else {
      ImGui::Text("object %d: seen", id);
    }
  }
}

void SessionPanel::timing(const PanelInput& in) {
  const session::CycleRecord& r = in.record;
  const double budget = session::cycleBudgetMs(in.settings);
  heading("cycle");
  ImGui::Text("budget %.1f ms (one EEG block); overruns: %d; late frames: %lld", budget, r.overruns,
              static_cast<long long>(r.presentation.late_frames));
  ImGui::TextUnformatted(session::eegClockLine(r).c_str());
  if (!r.eeg.fault.empty())
    ImGui::TextColored(ImVec4(1.0f, 0.35f, 0.3f, 1.0f), "EEG source: %s", r.eeg.fault.c_str());
  if (const std::string warning = session::timingWarning(r, in.settings); !warning.empty())
    ImGui::TextColored(ImVec4(1.0f, 0.6f, 0.2f, 1.0f), "%s", warning.c_str());
  if (ImGui::BeginTable(
          "timing", 6,
          ImGuiTableFlags_Borders | ImGuiTableFlags_RowBg | ImGuiTableFlags_SizingFixedFit)) {
    for (const char* h : {"stage", "last ms", "p50", "p90", "p99", "max"})
      ImGui::TableSetupColumn(h);
    ImGui::TableHeadersRow();
    for (const StageTiming& t : in.window.timing()) {
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(t.stage.c_str());
      for (double v : {t.last_ms, t.p50_ms, t.p90_ms, t.p99_ms, t.max_ms}) {
        ImGui::TableNextColumn();
        ImGui::Text("%.2f", v);
      }
    }
    ImGui::EndTable();
  }
  // The plot's scale, stated: its top is 1.2 blocks, its bottom zero.
  const std::vector<float>& history = in.window.recentCycles();
  const float top = static_cast<float>(budget * 1.2);
  char scale[64];
  std::snprintf(scale, sizeof scale, "0 to %.0f ms (budget %.1f)", top, budget);
  ImGui::PlotLines("cycle ms", history.data(), static_cast<int>(history.size()), 0, scale, 0.0f,
                   top, ImVec2(0, 60));
}

}  // namespace

PanelRegistry::Entry sessionPanel() {
  PanelParts parts{[] { return std::make_unique<SessionPanel>(); }};
  parts.shots.push_back({"session",
                         "during the grid's flashing",
                         [](const session::CycleRecord& r) {
                           return r.paradigm.phase == bci::Phase::CellFlashing &&
                                  r.paradigm.sequence >= 2;
                         },
                         {},
                         true});
  return {"session",
          "the phase, start/pause/resume/abort, the sequence, the selections, the cycle's timing",
          std::move(parts)};
}

}  // namespace arbci::ui
