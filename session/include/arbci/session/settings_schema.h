// The session file's schema: one table per section, composed of the keys each module declares
// where its structs live (bci/settings.h, vision/settings.h) and the session's own. From it come
// SessionConfig's parser and messages, the defaults a run uses when a file leaves a key out,
// the settings panel and docs/settings.md (`arbci settings --markdown`).
#pragma once

#include <string>

#include "arbci/core/schema.h"
#include "arbci/session/session_config.h"

namespace arbci::session {

const core::Schema<SessionConfig>& sessionSchema();
// Its sections that commands take options from: the calibration run's classifier, the ErrP's.
const core::Schema<ClassifierSettings>& classifierSchema();
const core::Schema<ErrpSettings>& errpOwnSchema();

// The session file's key at a dotted path ("lsl.scope", "paradigm.trials"), for a command's
// option made from it; std::logic_error naming the path when there is none.
const core::Key& sessionKey(const std::string& path);

// docs/settings.md: every section's table, then the registries' members (EEG sources,
// classifiers, marker families, camera sources, robot drivers; the application adds its panels).
std::string settingsMarkdown();

}  // namespace arbci::session
