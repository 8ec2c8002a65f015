// A GoogleTest fixture for the core suites: one owned Vulkan context per suite, or one for the
// whole run where the program's main asks for it (core_test_main.cpp); lavapipe on these machines,
// with the validation layer on unless STEADYXR_NO_VALIDATION is set, and every test failing when it
// raised a validation message.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <memory>
#include <string>

#include "steadyxr/core/vulkan_context.h"

namespace steadyxr::test {

class ValidatedContextTest : public ::testing::Test {
 public:
  // Keep one context for the whole run instead of one per suite, so that every suite's filters share
  // its compiled pipelines (lavapipe compiles a pass in about 0.4 s). The test program's main sets
  // it and registers SharedContextEnvironment, which destroys the context after the last suite.
  inline static bool shareAcrossSuites = false;
  static void destroySharedContext() { ctx_.reset(); }

 protected:
  static void SetUpTestSuite() {
    if (ctx_) return;  // shared across suites
    core::OwnedContextOptions o;
    o.enableValidation = std::getenv("STEADYXR_NO_VALIDATION") == nullptr;
    std::string err;
    ctx_ = core::VulkanContext::createOwned(o, &err);
    ASSERT_TRUE(ctx_) << err;
  }
  static void TearDownTestSuite() {
    if (!shareAcrossSuites) ctx_.reset();
  }
  void SetUp() override {
    ASSERT_TRUE(ctx_);
    before_ = ctx_->validationMessageCount();
  }
  void TearDown() override {
    const auto msgs = ctx_->validationMessages();
    EXPECT_EQ(msgs.size(), before_) << "validation: " << (msgs.size() > before_ ? msgs[before_] : "");
  }

  inline static std::unique_ptr<core::VulkanContext> ctx_;
  size_t before_ = 0;
};

// Destroys the shared context after the last suite (before static destruction, while the Vulkan
// loader and Mesa are still whole).
class SharedContextEnvironment : public ::testing::Environment {
 public:
  void TearDown() override { ValidatedContextTest::destroySharedContext(); }
};

}  // namespace steadyxr::test
