// `arbci robot keygen` writes a shared key; `arbci robot ... status|home|stop|reset|grasp|drop`
// talks to a backend from the shell, waits for the outcome and exits 0 only on success. It gives
// one of three honest answers about a motion: it ran (0 when it succeeded, 3 when it failed, was
// stopped, or its outcome was lost), it did not run (1: the backend said so, or it was never
// sent), or nobody can tell (4: the backend restarted or fell silent after it may have received
// it). A motion it cannot confirm is STOPped, so it never runs on unsupervised.
#include <chrono>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <optional>
#include <thread>

#include "arbci/robot/client.h"
#include "arbci/robot/key_file.h"
#include "arbci/robot/settings.h"
#include "robot_cli/robot_command.h"
#include "support/cli_error.h"
#include "support/schema_option.h"

namespace arbci::app {
namespace {

struct RobotOptions {
  std::string host, key_file, out;  // robot.host, robot.key_file
  int port = 0;                     // robot.port
  double timeout_s = 120.0;
  double retry_budget_s = 15.0;
  std::vector<double> xyz;
  bool force = false;
};

void printStatus(const robot::StatusPayload& s) {
  std::cout << std::fixed << std::setprecision(3) << "state: " << robot::toString(s.state)
            << "\ntool: (" << s.tool.x << ", " << s.tool.y << ", " << s.tool.z
            << ") m\ngripper: " << (s.gripper_opening > 0.5 ? "open" : "closed")
            << "\nholding: " << (s.holding >= 0 ? "object " + std::to_string(s.holding) : "nothing")
            << "\n";
  if (!s.stop_reason.empty())
    std::cout << "stopped: " << s.stop_reason << " (motion refused until `arbci robot reset`)\n";
  if (s.current_command != robot::MessageType::Status) {
    std::cout << "command: " << robot::toString(s.current_command) << " " << s.current_sequence
              << ", " << std::setprecision(0) << s.progress * 100.0 << "% done\n"
              << std::setprecision(3);
  }
  for (const robot::WorldObject& o : s.objects) {
    std::cout << "object " << o.id << ": (" << o.position.x << ", " << o.position.y << ", "
              << o.position.z << ")" << (o.held ? " held" : "") << "\n";
  }
}

using Seconds = std::chrono::duration<double>;

// Why the backend never bound us: its key differs (it said so), or nothing answered.
std::string noAnswer(const robot::RobotClient& client, const robot::Endpoint& endpoint,
                     double budget_s) {
  if (client.keyRefused())
    return "the backend at " + endpoint.toString() +
           " answered that our key is not its key: give both sides the same key file "
           "(--key-file here, arbci-robotd --key-file there)";
  return "no answer from the backend at " + endpoint.toString() + " in " +
         std::to_string(static_cast<int>(budget_s)) +
         " s (is arbci-robotd running, with the same key?)";
}

robot::RobotClient connect(const RobotOptions& o, robot::Endpoint& endpoint) {
  robot::Key key;
  try {
    key = robot::loadKey(o.key_file);
    endpoint = robot::Endpoint::resolve(o.host, o.port);
  } catch (const std::exception& error) {
    throw CliError(error.what());
  }
  robot::ClientOptions options;
  options.give_up_s = o.retry_budget_s;
  return robot::RobotClient(endpoint, key, options);
}

// Polls for `seconds`, or until `done` says so.
template <typename Done>
void pollFor(robot::RobotClient& client, double seconds, Done done) {
  const auto end = std::chrono::steady_clock::now() + Seconds(seconds);
  while (std::chrono::steady_clock::now() < end && !done()) {
    client.poll();
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

std::string armState(const robot::StatusPayload& s) {
  char tool[96];
  std::snprintf(tool, sizeof tool, "(%.3f, %.3f, %.3f)", s.tool.x, s.tool.y, s.tool.z);
  return std::string("the arm is ") + robot::toString(s.state) + ", holding " +
         (s.holding >= 0 ? "object " + std::to_string(s.holding) : std::string("nothing")) +
         ", tool at " + tool + " m";
}

// The motion could not be confirmed: STOP it (so it never runs on, or later), then ask the
// backend whether it ran. Always throws: 3 when it ran, 1 when the same backend run shows it did
// not (and after the STOP it never will), 4 when nobody can tell (the backend restarted, or the
// STOP was not confirmed either); the arm's state as the backend reports it now goes with it.
[[noreturn]] void stopUnconfirmed(robot::RobotClient& client, robot::MessageType type,
                                  std::uint64_t sequence, const std::string& why, bool restarted) {
  const std::string name = robot::toString(type);
  const std::uint64_t stop = client.send(robot::MessageType::Stop);
  bool stopped = false;
  pollFor(client, 5.0, [&] {
    for (const robot::RobotEvent& e : client.takeEvents()) {
      stopped |= e.sequence == stop && e.kind == robot::RobotEvent::Kind::Finished;
      restarted |= e.kind == robot::RobotEvent::Kind::Restarted;
    }
    return stopped;
  });
  bool ran = client.accepted(sequence) && !restarted;
  std::optional<robot::StatusPayload> now;
  if (stopped) {
    client.requestStatus();
    const auto asked = std::chrono::steady_clock::now();
    pollFor(client, 1.0, [&] {
      const auto& s = client.status();
      // A status answered after the STOP was accepted: the backend's state now.
      if (s && std::chrono::steady_clock::now() - asked > std::chrono::milliseconds(250)) now = s;
      return now.has_value();
    });
    if (now && !restarted)
      ran |= now->last_finished_sequence == sequence ||
             (now->current_is_yours && now->current_sequence == sequence);
  }
  const std::string stop_note =
      stopped ? "STOP sent and accepted: motion is refused until `arbci robot reset`"
              : "STOP sent but not confirmed either: check the arm";
  const std::string state = now ? "; " + armState(*now) : "";
  if (client.accepted(sequence) && restarted)
    throw CliError(
        name + " ran, then the backend restarted during it (" + why + "); " + stop_note + state, 3);
  if (ran)
    throw CliError(name + " ran, but the answer was lost (" + why + "); " + stop_note + state, 3);
  if (stopped && !restarted)
    throw CliError(
        name + " not run: " + why + "; the backend shows it never ran, and " + stop_note + state,
        1);
  throw CliError(name + ": unknown, it may have run: " + why + "; " + stop_note + state, 4);
}

int talk(const RobotOptions& o, robot::MessageType type) {
  robot::Endpoint endpoint;
  robot::RobotClient client = connect(o, endpoint);
  const std::string name = robot::toString(type);
  const robot::Vec3 target =
      o.xyz.size() == 3 ? robot::Vec3{o.xyz[0], o.xyz[1], o.xyz[2]} : robot::Vec3{};
  const bool motion = robot::isMotion(type);
  const auto start = std::chrono::steady_clock::now();
  const std::uint64_t sequence = type == robot::MessageType::Status ? 0 : client.send(type, target);
  bool told_silent = false, ever_connected = false, restarted = false;
  using Kind = robot::RobotEvent::Kind;
  while (Seconds(std::chrono::steady_clock::now() - start).count() < o.timeout_s) {
    client.poll();
    for (const robot::RobotEvent& e : client.takeEvents()) {
      if (e.kind == Kind::Silent && !told_silent) {
        // Not fatal: the retry budget is used in full (a lossy link answers eventually).
        told_silent = true;
        std::cerr << "no answer yet from the backend at " << endpoint.toString()
                  << "; retrying for up to " << o.retry_budget_s << " s\n";
      }
      if (e.kind == Kind::Restarted) {
        restarted = true;
        std::cerr << "the backend restarted\n";
      }
      ever_connected |= e.kind == Kind::Connected;
      if (e.sequence != sequence || sequence == 0) continue;
      if (e.kind == Kind::Accepted) std::cerr << name << " accepted\n";
      if (e.kind == Kind::Rejected)
        throw CliError(name + " not run: rejected: " + robot::toString(e.reason) + ": " + e.text);
      if (e.kind == Kind::Failed) {
        // Commands go out only once bound to a backend run: never bound, never sent.
        if (!ever_connected)
          throw CliError(name + " not run: " + noAnswer(client, endpoint, o.retry_budget_s));
        if (!e.may_have_run) throw CliError(e.text, 1);
        if (motion) stopUnconfirmed(client, type, sequence, e.text, restarted);
        throw CliError(name + ": unknown, it may have taken effect: " + e.text, 4);
      }
      if (e.kind == Kind::Finished) {
        if (e.outcome != robot::Outcome::Success)
          throw CliError(name + " ran: " + robot::toString(e.outcome) + ": " + e.text, 3);
        std::cout << name << " finished: " << e.text << "\n";
        return 0;
      }
    }
    if (sequence == 0 && client.status()) {
      printStatus(*client.status());
      return 0;
    }
    if (sequence == 0 && !client.connected() &&
        Seconds(std::chrono::steady_clock::now() - start).count() > o.retry_budget_s) {
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  if (sequence == 0 || !client.connected())
    throw CliError(noAnswer(client, endpoint, o.retry_budget_s));
  if (motion)
    stopUnconfirmed(client, type, sequence,
                    "no outcome within " + std::to_string(static_cast<int>(o.timeout_s)) + " s",
                    restarted);
  throw CliError(
      name + ": unknown, no outcome within " + std::to_string(static_cast<int>(o.timeout_s)) + " s",
      4);
}

}  // namespace

void addRobotCommand(CLI::App& root, int& exit_code) {
  auto o = std::make_shared<RobotOptions>();
  CLI::App* robot_cmd = root.add_subcommand(
      "robot",
      "Talk to a robot backend (arbci-robotd) or make a key for it.\n"
      "Commands wait for FINISHED. Exit 0: it ran and succeeded; 1: it did not run (the backend\n"
      "refused it or shows it never ran, or no backend answered, so it was never sent); 3: it\n"
      "ran but failed, was stopped, or its outcome was lost; 4: unknown, it may have run (the\n"
      "backend restarted or fell silent after it may have received it: the arm's state is\n"
      "printed when the backend can say). A motion that cannot be confirmed is followed by a\n"
      "STOP, which stays in force until `arbci robot reset`.");
  robot_cmd->require_subcommand(1);
  schemaOption(*robot_cmd, "--host", o->host, robot::clientLinkSchema().at("host"));
  schemaOption(*robot_cmd, "--port", o->port, robot::clientLinkSchema().at("port"));
  schemaOption(*robot_cmd, "--key-file", o->key_file, robot::clientLinkSchema().at("key_file"));
  robot_cmd->add_option("--timeout", o->timeout_s, "seconds to wait for the outcome")
      ->capture_default_str();
  robot_cmd
      ->add_option("--retry-budget", o->retry_budget_s,
                   "seconds to keep retransmitting a command nobody has accepted yet")
      ->capture_default_str()
      ->check(CLI::Range(0.1, 600.0));

  CLI::App* keygen = robot_cmd->add_subcommand(
      "keygen",
      "Write a fresh random key (64 hex characters and a newline, mode 0600) to a new file;\n"
      "an existing key is replaced only with --force, anything but a regular file never");
  keygen->add_option("--out", o->out, "key file to write (a new file)")->required();
  keygen->add_flag("--force", o->force, "replace an existing key file");
  keygen->callback([o, &exit_code] {
    try {
      robot::saveKey(o->out, robot::generateKey(), o->force);
    } catch (const robot::KeyError& error) {
      throw CliError(error.what());
    }
    std::cout << "wrote " << o->out << " (readable by its owner only)\n";
    exit_code = 0;
  });
  auto command = [&, o](const char* name, const char* help, robot::MessageType type,
                        bool with_target) {
    CLI::App* c = robot_cmd->add_subcommand(name, help);
    if (with_target)
      c->add_option("X Y Z", o->xyz, "target in the robot frame, metres")->expected(3)->required();
    c->callback([o, type, &exit_code] {
      if (o->key_file.empty()) throw CliError("--key-file is required to talk to the backend");
      exit_code = talk(*o, type);
    });
  };
  command("status", "Print the backend's state, tool position, gripper and world",
          robot::MessageType::Status, false);
  command("home", "Move to the home position", robot::MessageType::Home, false);
  command("stop",
          "Emergency stop: halt at once; motion commands are refused until `arbci robot reset`",
          robot::MessageType::Stop, false);
  command("reset", "End a stop (STOP or the watchdog's halt): motion commands are taken again",
          robot::MessageType::Reset, false);
  command("grasp", "Grasp the object at X Y Z and lift it", robot::MessageType::Grasp, true);
  command("drop", "Put the held object down at X Y Z", robot::MessageType::Drop, true);
}

}  // namespace arbci::app
