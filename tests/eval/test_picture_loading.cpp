// The pictures a user names (--images) are measured as given or not at all: a name that does not load
// stops the run with a message that says what was looked for, where the old loader measured a
// checkerboard under the picture's name (round 25 found it with python3-skimage's JPEGs).
#include "image.h"
#include "scene.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace steadyxr::eval {
namespace {

namespace fs = std::filesystem;

// A folder of its own under the system's temporary directory, removed with the test.
class PictureFolder : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / ("steadyxr-pictures-" + std::string(info->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  void writeBytes(const std::string& name, const std::string& bytes) const {
    std::ofstream(path(name), std::ios::binary) << bytes;
  }
  void writePng(const std::string& name, int width, int height) const {
    Image img(width, height, 0.5f);
    std::string error;
    ASSERT_TRUE(savePng(path(name), img, &error)) << error;
  }

  fs::path dir_;
};

TEST_F(PictureFolder, ReadsAPngByNameInTheFolderAndByPath) {
  writePng("stripes.png", 3, 2);
  Rgba8 img;
  std::string error;
  ASSERT_TRUE(loadPicture("stripes", dir_.string(), &img, &error)) << error;
  EXPECT_EQ(img.width, 3);
  EXPECT_EQ(img.height, 2);
  Rgba8 byPath;
  ASSERT_TRUE(loadPicture(path("stripes.png"), "/nonexistent", &byPath, &error)) << error;
  EXPECT_EQ(byPath.width, 3);
}

TEST_F(PictureFolder, AMissingPictureIsAnErrorThatNamesWhereItLooked) {
  Rgba8 img;
  std::string error;
  EXPECT_FALSE(loadPicture("nosuchpicture", dir_.string(), &img, &error));
  EXPECT_NE(error.find("picture 'nosuchpicture' not found"), std::string::npos) << error;
  EXPECT_NE(error.find(path("nosuchpicture.png")), std::string::npos) << error;
}

// python3-skimage ships rocket, retina and hubble_deep_field as JPEG: the message points at the file.
TEST_F(PictureFolder, APictureInAnotherFormatIsNamedWithWhatToDo) {
  writeBytes("rocket.jpg", "\xff\xd8\xff\xe0 not a png");
  Rgba8 img;
  std::string error;
  EXPECT_FALSE(loadPicture("rocket", dir_.string(), &img, &error));
  EXPECT_NE(error.find(path("rocket.jpg") + " is there"), std::string::npos) << error;
  EXPECT_NE(error.find("PNG only"), std::string::npos) << error;
}

TEST_F(PictureFolder, AFileThatIsNotAPngIsAnErrorNotAPicture) {
  writeBytes("broken.png", "not a png at all");
  Rgba8 img;
  std::string error;
  EXPECT_FALSE(loadPicture("broken", dir_.string(), &img, &error));
  EXPECT_NE(error.find("is not a PNG steadyxr-eval can read"), std::string::npos) << error;
}

// The scenes' own extra pictures (a video's second shot) still fall back, and say so.
TEST_F(PictureFolder, TheScenesOwnPicturesFallBackToACheckerboardWithAWarning) {
  std::string warning;
  const Rgba8 img = loadTextureOrFallback("coffee", dir_.string(), &warning);
  EXPECT_EQ(img.width, 256);
  EXPECT_EQ(img.height, 256);
  EXPECT_NE(warning.find("using a checkerboard"), std::string::npos) << warning;
}

}  // namespace
}  // namespace steadyxr::eval
