// The robot drivers' cost per step: each driver runs grasps, put-downs and homes over the
// default session's table, stepped 2 ms of robot time at a time (the physics driver's own
// timestep, 500 Hz), and the wall time of every step is kept. Prints median, p99 and maximum per
// driver (docs/robot.md has the figures). One thread; pin it with taskset for one core.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>
#include <memory>
#include <vector>

#include "arbci/robot/mujoco_arm.h"
#include "arbci/robot/simulated_arm.h"

namespace {

using namespace arbci::robot;

RobotConfig defaultTable() {
  RobotConfig c;
  for (int k = 0; k < 4; ++k)
    c.objects.push_back({10 * (k + 1), {-0.27 + 0.18 * k, 0.42, 0.06}, 0.06, 0.035});
  return c;
}

struct Figures {
  double median_us, p99_us, max_us;
  long steps;
  int failed;
};

Figures measure(RobotDriver& arm, int trials) {
  const double dt = 0.002;
  std::vector<double> us;
  int failed = 0;
  const Vec3 cells[3] = {{0.09, 0.75, 0.0}, {-0.09, 0.57, 0.0}, {0.0, 0.66, 0.0}};
  for (int t = 0; t < trials; ++t) {
    const int k = t % 4;
    const Vec3 object = {-0.27 + 0.18 * k, 0.42, 0.06};
    const Vec3 cell = cells[t % 3];
    // Out to the cell and back, so the table is the same for the next trial.
    const DriverCommand commands[] = {{MessageType::Grasp, object},
                                      {MessageType::Drop, cell},
                                      {MessageType::Grasp, {cell.x, cell.y, 0.06}},
                                      {MessageType::Drop, {object.x, object.y, 0.0}},
                                      {MessageType::Home, {}}};
    for (const DriverCommand& c : commands) {
      if (arm.check(c)) {
        ++failed;
        continue;
      }
      arm.start(c);
      for (int i = 0; i < 100000; ++i) {
        const auto start = std::chrono::steady_clock::now();
        const auto result = arm.step(dt);
        us.push_back(
            std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start)
                .count());
        if (result) {
          if (result->outcome != Outcome::Success) ++failed;
          break;
        }
      }
    }
  }
  std::sort(us.begin(), us.end());
  return {us[us.size() / 2], us[us.size() * 99 / 100], us.back(), static_cast<long>(us.size()),
          failed};
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"The robot drivers' step cost (2 ms of robot time per step)"};
  int trials = 6;
  app.add_option("--trials", trials, "grasp-and-put-down trials per driver")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  const RobotConfig table = defaultTable();
  struct Driver {
    const char* name;
    std::function<std::unique_ptr<RobotDriver>()> make;
  };
  const Driver drivers[] = {
      {"simulated (kinematic, KDL)", [&] { return std::make_unique<SimulatedArm>(table); }},
      {"mujoco, arm6", [&] { return std::make_unique<MujocoArm>(table); }},
      {"mujoco, arm7", [&] {
         RobotConfig c = table;
         c.model = "arm7";
         return std::make_unique<MujocoArm>(c);
       }}};
  std::printf("| driver | steps | median us | p99 us | max us | commands failed |\n");
  std::printf("| --- | --- | --- | --- | --- | --- |\n");
  for (const Driver& d : drivers) {
    auto arm = d.make();
    const Figures f = measure(*arm, trials);
    std::printf("| %s | %ld | %.1f | %.1f | %.1f | %d |\n", d.name, f.steps, f.median_us, f.p99_us,
                f.max_us, f.failed);
  }
}
