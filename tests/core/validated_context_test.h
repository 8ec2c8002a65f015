// A GoogleTest fixture for the core suites: one owned Vulkan context per suite (lavapipe on these
// machines), with the validation layer on unless STEADYXR_NO_VALIDATION is set, and every test
// failing when it raised a validation message.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <memory>
#include <string>

#include "steadyxr/core/vulkan_context.h"

namespace steadyxr::test {

class ValidatedContextTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    core::OwnedContextOptions o;
    o.enableValidation = std::getenv("STEADYXR_NO_VALIDATION") == nullptr;
    std::string err;
    ctx_ = core::VulkanContext::createOwned(o, &err);
    ASSERT_TRUE(ctx_) << err;
  }
  static void TearDownTestSuite() { ctx_.reset(); }
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

}  // namespace steadyxr::test
