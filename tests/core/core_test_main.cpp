// The GPU suite's main: one validated context for every suite (ValidatedContextTest), so that the
// suites' filters share its compiled pipelines.
#include <gtest/gtest.h>

#include "validated_context_test.h"

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  steadyxr::test::ValidatedContextTest::shareAcrossSuites = true;
  ::testing::AddGlobalTestEnvironment(new steadyxr::test::SharedContextEnvironment);  // gtest owns it
  return RUN_ALL_TESTS();
}
