#include "arbci/session/trial_intents.h"

#include <map>
#include <random>
#include <tuple>

#include "arbci/core/seeds.h"

namespace arbci::session {

std::vector<TrialIntent> intendedTrials(const SessionConfig& config) {
  std::vector<TrialIntent> intended = config.intended;
  std::map<int, std::pair<int, int>> cell_of;  // objects standing on the grid
  for (const TrialIntent& t : intended) cell_of[t.object] = {t.row, t.column};
  std::mt19937_64 random(core::seedOf(config.eeg.seed, core::RandomStream::TrialIntents));
  const auto& objects = config.world.objects;
  const int rows = config.world.grid.rows, columns = config.world.grid.columns;
  // With more objects than cells some must share: then any cell will do.
  const bool any_cell = objects.size() > static_cast<size_t>(rows * columns);
  while (static_cast<int>(intended.size()) < config.paradigm.trials) {
    TrialIntent t;
    t.object = objects[random() % objects.size()].id;
    std::vector<std::pair<int, int>> free;
    for (int row = 1; row <= rows; ++row) {
      for (int column = 1; column <= columns; ++column) {
        bool taken = false;
        for (const auto& [id, cell] : cell_of)
          taken |= id != t.object && cell == std::pair{row, column};
        if (!taken || any_cell) free.emplace_back(row, column);
      }
    }
    std::tie(t.row, t.column) = free[random() % free.size()];
    cell_of[t.object] = {t.row, t.column};
    intended.push_back(t);
  }
  return intended;
}

}  // namespace arbci::session
