// TimeSettings::step_from (fluid_model.hpp): the step of a transient run, the case's Δt unless
// end_time is closer by more than round-off, so that a run ending at a multiple of Δt takes the
// same steps as a longer run (a restart from its last checkpoint then continues bit for bit).

#include <gtest/gtest.h>

#include "coapt/fluid/fluid_model.hpp"

namespace {

coapt::fluid::TimeSettings settings(double end_time, double time_step) {
  coapt::fluid::TimeSettings t;
  t.steady = false;
  t.end_time = end_time;
  t.time_step = time_step;
  return t;
}

TEST(FluidTimeSettings, StepsOfAMultipleOfTheStepAreTheSameAsInALongerRun) {
  const auto short_run = settings(0.04, 0.002), long_run = settings(0.044, 0.002);
  double t_short = 0, t_long = 0;
  int steps = 0;
  while (t_short < short_run.end_time * (1 - 1e-12)) {
    const double dt = short_run.step_from(t_short);
    EXPECT_EQ(dt, long_run.step_from(t_long)) << "step " << steps + 1;
    t_short += dt;
    t_long += long_run.step_from(t_long);
    ++steps;
  }
  EXPECT_EQ(steps, 20);
  EXPECT_EQ(t_short, t_long);  // both carry the same round-off (0.04 + 2e-17)
  EXPECT_EQ(short_run.n_steps(), 20);
}

TEST(FluidTimeSettings, TheLastStepIsShorterWhenEndTimeIsNotAMultiple) {
  const auto t = settings(0.045, 0.002);
  EXPECT_EQ(t.n_steps(), 23);
  EXPECT_NEAR(t.step_from(0.044), 0.001, 1e-15);
  EXPECT_EQ(t.step_from(0.0), 0.002);
}

}  // namespace
