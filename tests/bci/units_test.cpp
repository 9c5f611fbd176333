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

}  // namespace
}  // namespace arbci::bci
