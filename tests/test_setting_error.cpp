// Library messages name settings, never command-line flags (core/setting_error.hpp); each
// tool words them as its flags (cli/setting_words.hpp), so that its user reads the line the
// tool always printed.
#include <gtest/gtest.h>

#include <string>

#include "cli/setting_words.hpp"
#include "core/errors.hpp"
#include "core/setting_error.hpp"
#include "pulse/pulse_solver.hpp"
#include "pulse/solution_breakdown.hpp"
#include "tests/network_builders.hpp"

using namespace hemotree;

TEST(SettingWords, PlaceholdersBecomeTheToolsWordsOrTheSettingsNames) {
  const std::string text = "try a smaller " + placeholder("dt") + " or " + placeholder("lumped_step");
  EXPECT_EQ(in_words(text), "try a smaller dt or lumped_step");
  EXPECT_EQ(in_words(text, hemosolve_words()), "try a smaller --dt or --lumped-step");
  EXPECT_EQ(in_words(text, {{"dt", "time_step="}}), "try a smaller time_step= or lumped_step");
  EXPECT_EQ(first_setting(text), "dt");
  EXPECT_EQ(first_setting("no setting here"), "");
}

TEST(SettingWords, WhatTheUserWroteIsNeverReworded) {
  // Braces, and stray control characters that frame no name, pass through as they are.
  const std::string user = "--out /tmp/{dt}/run \x02 a \x03 b \x02Dt\x03 \x02";
  EXPECT_EQ(in_words(user, hemosolve_words()), user);
  EXPECT_EQ(in_words(placeholder("out") + " " + user, hemosolve_words()), "--out " + user);
}

TEST(SettingError, NamesItsSettingAndIsWordedByTheTool) {
  try {
    throw SettingError("degree", placeholder("degree") + " must be at least 0");
  } catch (const InputError& e) {  // an input error like any other: exit status 2
    EXPECT_STREQ(e.what(), "degree must be at least 0");
    const auto* setting = dynamic_cast<const SettingError*>(&e);
    ASSERT_NE(setting, nullptr);
    EXPECT_EQ(setting->setting(), "degree");
    EXPECT_EQ(setting->in_words(hemosolve_words()), "--degree must be at least 0");
  }
  EXPECT_THROW(throw_input_error("plain"), InputError);
  try {
    throw_input_error("a.vtp: read in m (" + placeholder("unit") + " sets another)");
  } catch (const SettingError& e) {
    EXPECT_EQ(e.setting(), "unit");
    EXPECT_EQ(e.in_words(vimport_words()), "a.vtp: read in m (--unit sets another)");
  }
}

TEST(SettingError, ThePulseSolverRefusesBySetting) {
  const Network net = test_networks::chain(1, 0.1, 1e-3, 1e5, 0.0, test_networks::newtonian(3.5e-3));
  SolverOptions options;
  options.elements = 0;
  try {
    PulseSolver solver(net, options);
    ADD_FAILURE() << "no refusal";
  } catch (const SettingError& e) {
    EXPECT_EQ(e.setting(), "elements");
    EXPECT_STREQ(e.what(), "elements must be at least 1");
    EXPECT_EQ(e.in_words(hemosolve_words()), "--elements must be at least 1");  // as hemosolve printed it
  }
  const SolutionBreakdown breakdown(7, 0.25);
  EXPECT_EQ(in_words(breakdown.message(), hemosolve_words()),
            "the solution broke down in vessel 7 at t = 0.25 s (area not positive or not finite); try a smaller "
            "time step (--dt or --cfl) or a lower degree (--degree)");
  EXPECT_EQ(std::string(breakdown.what()).find("--"), std::string::npos) << breakdown.what();
}
