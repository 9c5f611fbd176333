// Voltage units as EEG sources name them (XDF channel units, LSL stream descriptions, eegdev
// channel info, GDF/EDF/BDF physical dimensions read by BioSig): every source scales its samples
// to microvolts through this one table.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace arbci::bci {

// Microvolts per one `unit` ("V", "mV", "uV", "µV", "nV" or their spelled-out names, any case);
// 1 for microvolts, for an empty unit and for one not in the table (EEG's usual unit: devices and
// files that leave it out give microvolts).
double microvoltsPer(std::string_view unit);

// Whether `unit` is a voltage in the table, or empty (taken as microvolts); false for anything
// else ("counts", "bits", "degC"), whose values a reader keeps as they are and names.
bool isVoltageUnit(std::string_view unit);

// "channel(s) GSR ("uS"), X ("counts") are not in a voltage unit: ..." for the channels whose unit
// is not a voltage (units[k] of channels[k]; a missing unit is a voltage), or "" when every one
// is: the note a reader or a live source puts where the data go, so that no value is taken for
// microvolts unsaid.
std::string nonVoltageNote(const std::vector<std::string>& channels,
                           const std::vector<std::string>& units);

}  // namespace arbci::bci
