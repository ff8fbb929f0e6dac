// Test helper: the end-to-end accuracy tests that the sanitizer build (scripts/sanitize.sh, about
// 10x slower) leaves to the Release suite. Each names the test that runs the same code under the
// sanitizers, so memory and undefined-behaviour checking loses no code path, only a bound on
// accuracy that the Release run checks (docs/reliability.md, "CI").
#ifndef PLDVO_TESTS_SANITIZER_BUDGET_H_
#define PLDVO_TESTS_SANITIZER_BUDGET_H_

#include <gtest/gtest.h>

#ifdef PLDVO_SANITIZE
#define PLDVO_RELEASE_ONLY_ACCURACY_TEST(same_code_in)                                        \
  GTEST_SKIP() << "accuracy bounds: checked by the Release suite; under the sanitizers this " \
                  "code runs in "                                                             \
               << same_code_in
#else
#define PLDVO_RELEASE_ONLY_ACCURACY_TEST(same_code_in) static_cast<void>(same_code_in)
#endif

#endif  // PLDVO_TESTS_SANITIZER_BUDGET_H_
