// The BIDS options `arbci bids export` and `arbci run --bids` share, and how an export is told.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "bids/bids_export.h"

namespace arbci::app {

// --subject, --session, --task, --run, --age, --sex, --handedness; with `root_option`, also
// --bids ROOT.
void addBidsOptions(CLI::App* command, BidsEntities& entities, BidsParticipant& participant,
                    std::string& root, bool root_option);
void reportBidsExport(const BidsExport& done);

}  // namespace arbci::app
