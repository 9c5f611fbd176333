// `arbci robot keygen` writes a shared key; `arbci robot ... status|home|stop|grasp|drop` talks
// to a backend from the shell, waits for the outcome and exits 0 only on success.
#include <chrono>
#include <iomanip>
#include <iostream>
#include <thread>

#include "arbci/robot/client.h"
#include "arbci/robot/key_file.h"
#include "commands/commands.h"
#include "support/cli_error.h"
#include "support/output_path.h"

namespace arbci::app {
namespace {

struct RobotOptions {
  std::string host = "127.0.0.1", key_file, out;
  int port = 47800;
  double timeout_s = 120.0;
  std::vector<double> xyz;
};

void printStatus(const robot::StatusPayload& s) {
  std::cout << std::fixed << std::setprecision(3) << "state: " << robot::toString(s.state)
            << "\ntool: (" << s.tool.x << ", " << s.tool.y << ", " << s.tool.z
            << ") m\ngripper: " << (s.gripper_opening > 0.5 ? "open" : "closed")
            << "\nholding: " << (s.holding >= 0 ? "object " + std::to_string(s.holding) : "nothing")
            << "\n";
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

int talk(const RobotOptions& o, robot::MessageType type) {
  robot::Key key;
  robot::Endpoint endpoint;
  try {
    key = robot::loadKey(o.key_file);
    endpoint = robot::Endpoint::resolve(o.host, o.port);
  } catch (const std::exception& error) {
    throw CliError(error.what());
  }
  robot::RobotClient client(endpoint, key);
  const robot::Vec3 target =
      o.xyz.size() == 3 ? robot::Vec3{o.xyz[0], o.xyz[1], o.xyz[2]} : robot::Vec3{};
  const auto start = std::chrono::steady_clock::now();
  const std::uint64_t sequence = type == robot::MessageType::Status ? 0 : client.send(type, target);
  while (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() <
         o.timeout_s) {
    client.poll();
    for (const robot::RobotEvent& e : client.takeEvents()) {
      using Kind = robot::RobotEvent::Kind;
      if (e.kind == Kind::Silent && (sequence == 0 || client.busy())) {
        throw CliError("no answer from the backend at " + endpoint.toString() +
                       " (is arbci-robotd running, with the same key?)");
      }
      if (e.sequence != sequence || sequence == 0) continue;
      if (e.kind == Kind::Accepted) std::cerr << robot::toString(type) << " accepted\n";
      if (e.kind == Kind::Rejected)
        throw CliError(std::string(robot::toString(type)) +
                       " rejected: " + robot::toString(e.reason) + ": " + e.text);
      if (e.kind == Kind::Failed) throw CliError(e.text);
      if (e.kind == Kind::Finished) {
        if (e.outcome != robot::Outcome::Success)
          throw CliError(std::string(robot::toString(type)) + " " + robot::toString(e.outcome) +
                         ": " + e.text);
        std::cout << robot::toString(type) << " finished: " << e.text << "\n";
        return 0;
      }
    }
    if (sequence == 0 && client.status()) {
      printStatus(*client.status());
      return 0;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  throw CliError(std::string(robot::toString(type)) + ": no outcome within " +
                 std::to_string(static_cast<int>(o.timeout_s)) + " s");
}

}  // namespace

void addRobotCommand(CLI::App& root, int& exit_code) {
  auto o = std::make_shared<RobotOptions>();
  CLI::App* robot_cmd = root.add_subcommand(
      "robot",
      "Talk to a robot backend (arbci-robotd) or make a key for it.\n"
      "Commands wait for FINISHED: exit 0 on success, 1 with the reason otherwise.");
  robot_cmd->require_subcommand(1);
  robot_cmd->add_option("--host", o->host, "backend address")->capture_default_str();
  robot_cmd->add_option("--port", o->port, "backend UDP port")
      ->capture_default_str()
      ->check(CLI::Range(1, 65535));
  robot_cmd->add_option("--key-file", o->key_file, "the shared key (arbci robot keygen)");
  robot_cmd->add_option("--timeout", o->timeout_s, "seconds to wait for the outcome")
      ->capture_default_str();

  CLI::App* keygen = robot_cmd->add_subcommand(
      "keygen", "Write a fresh random key (64 hex characters, mode 0600)");
  keygen->add_option("--out", o->out, "key file to write")->required();
  keygen->callback([o, &exit_code] {
    ensureWritable(o->out);
    try {
      robot::saveKey(o->out, robot::generateKey());
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
  command("stop", "Emergency stop: halt at once", robot::MessageType::Stop, false);
  command("grasp", "Grasp the object at X Y Z and lift it", robot::MessageType::Grasp, true);
  command("drop", "Put the held object down at X Y Z", robot::MessageType::Drop, true);
}

}  // namespace arbci::app
