// TimingFaultTolerance: what error() answers for the faults the framework reports.

#include "chimera/module/fault_tolerance.hpp"

#include <gtest/gtest.h>

namespace chimera {
namespace {

CycleTiming fault_at(std::uint64_t cycle, Fault fault) {
  CycleTiming t;
  t.cycle = cycle;
  t.fault = fault;
  return t;
}

TEST(TimingFaultTolerance, RecoversFromScatteredTimingFaults) {
  TimingFaultTolerance tolerance(3);
  for (std::uint64_t cycle : {5, 9, 20, 22, 40})
    EXPECT_TRUE(tolerance.judge(fault_at(cycle, Fault::kDeadlineMissed)).is_ok()) << cycle;
  EXPECT_TRUE(tolerance.judge(fault_at(41, Fault::kBudgetOverrun)).is_ok());
}

TEST(TimingFaultTolerance, FailsWhenTheLimitComesInARow) {
  TimingFaultTolerance tolerance(3);
  EXPECT_TRUE(tolerance.judge(fault_at(7, Fault::kDeadlineMissed)).is_ok());
  EXPECT_TRUE(tolerance.judge(fault_at(8, Fault::kDeadlineMissed)).is_ok());
  EXPECT_FALSE(tolerance.judge(fault_at(9, Fault::kDeadlineMissed)).is_ok());
}

TEST(TimingFaultTolerance, AMethodFailureIsNeverExcused) {
  TimingFaultTolerance tolerance(100);
  EXPECT_FALSE(tolerance.judge(fault_at(1, Fault::kMethodFailed)).is_ok());
  EXPECT_FALSE(tolerance.judge(fault_at(2, Fault::kNone)).is_ok());
}

}  // namespace
}  // namespace chimera
