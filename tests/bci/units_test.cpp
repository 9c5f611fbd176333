// Every EEG source scales its samples to microvolts through one table of unit names.
#include <gtest/gtest.h>

#include "arbci/bci/units.h"

namespace arbci::bci {
namespace {

TEST(Units, VoltageUnitsScaleToMicrovolts) {
  EXPECT_DOUBLE_EQ(microvoltsPer("V"), 1e6);
  EXPECT_DOUBLE_EQ(microvoltsPer("volts"), 1e6);
  EXPECT_DOUBLE_EQ(microvoltsPer("mV"), 1e3);
  EXPECT_DOUBLE_EQ(microvoltsPer("Millivolt"), 1e3);
  EXPECT_DOUBLE_EQ(microvoltsPer("nV"), 1e-3);
  EXPECT_DOUBLE_EQ(microvoltsPer("uV"), 1.0);
  EXPECT_DOUBLE_EQ(microvoltsPer("microvolts"), 1.0);
}

TEST(Units, AnUnnamedUnitIsTakenAsMicrovolts) {
  EXPECT_DOUBLE_EQ(microvoltsPer(""), 1.0);
}

// A unit that is not a voltage (an amplifier's raw counts) is not taken for one.
TEST(Units, OnlyVoltagesAndTheEmptyUnitAreVoltages) {
  for (const char* unit : {"", "V", "mV", "uV", "µV", "μV", "microvolts", "nV"})
    EXPECT_TRUE(isVoltageUnit(unit)) << unit;
  for (const char* unit : {"counts", "bits", "degC", "n/a"})
    EXPECT_FALSE(isVoltageUnit(unit)) << unit;
}

}  // namespace
}  // namespace arbci::bci
