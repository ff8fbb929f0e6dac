// The test render cache (tests/render_cache.h): a frame read back from the cache is the rendered
// frame bit for bit, a damaged cache file is rendered again, other options do not share an entry,
// and a sequence folder is written once.
#include "tests/render_cache.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "experiments/synthetic/synthetic_sequence.h"

namespace pldvo::test {
namespace {

namespace fs = std::filesystem;

synthetic::SyntheticSequence TinySequence(int seed) {
  synthetic::SynthOptions options;
  options.preset = "textured";
  options.frames = 3;
  options.seed = seed;
  options.width = 80;
  options.height = 60;
  options.fx = options.fy = 65.0;
  options.threads = 1;
  return synthetic::MakeSequence(options);
}

bool SameBytes(const cv::Mat& a, const cv::Mat& b) {
  return a.type() == b.type() && a.size() == b.size() && a.isContinuous() && b.isContinuous() &&
         std::memcmp(a.data, b.data, a.total() * a.elemSize()) == 0;
}

bool SameFrame(const synthetic::RenderedFrame& a, const synthetic::RenderedFrame& b) {
  return SameBytes(a.image, b.image) && SameBytes(a.depth, b.depth);
}

class RenderCacheTest : public ::testing::Test {
 protected:
  void SetUp() override { fs::remove_all(dir_); }
  void TearDown() override { fs::remove_all(dir_); }
  const fs::path dir_ =
      fs::temp_directory_path() / ("pldvo_render_cache_test_" + std::to_string(::getpid()));
};

TEST_F(RenderCacheTest, CachedFrameIsTheRenderedFrame) {
  const synthetic::SyntheticSequence sequence = TinySequence(1);
  const synthetic::RenderedFrame rendered = synthetic::RenderFrame(sequence, 2);
  ASSERT_GT(cv::countNonZero(rendered.depth), 0);
  const synthetic::RenderedFrame first = RenderFrameCached(sequence, 2, dir_);  // a miss
  int files = 0;
  for (const auto& entry : fs::directory_iterator(dir_))
    files += entry.path().extension() == ".frame";
  EXPECT_EQ(files, 1);
  const synthetic::RenderedFrame second = RenderFrameCached(sequence, 2, dir_);  // a hit
  EXPECT_TRUE(SameFrame(first, rendered));
  EXPECT_TRUE(SameFrame(second, rendered));
  // Another frame and another seed have their own entries.
  EXPECT_TRUE(SameFrame(RenderFrameCached(sequence, 1, dir_), synthetic::RenderFrame(sequence, 1)));
  const synthetic::SyntheticSequence other = TinySequence(2);
  EXPECT_TRUE(SameFrame(RenderFrameCached(other, 2, dir_), synthetic::RenderFrame(other, 2)));
  files = 0;
  for (const auto& entry : fs::directory_iterator(dir_))
    files += entry.path().extension() == ".frame";
  EXPECT_EQ(files, 3);
}

TEST_F(RenderCacheTest, DamagedEntryIsRenderedAgain) {
  const synthetic::SyntheticSequence sequence = TinySequence(1);
  RenderFrameCached(sequence, 0, dir_);
  for (const auto& entry : fs::directory_iterator(dir_)) {
    if (entry.path().extension() != ".frame") continue;
    fs::resize_file(entry.path(), fs::file_size(entry.path()) / 2);  // a truncated entry
  }
  EXPECT_TRUE(SameFrame(RenderFrameCached(sequence, 0, dir_), synthetic::RenderFrame(sequence, 0)));
}

// A hit returns what the entry holds (here an edited pixel) without rendering.
TEST_F(RenderCacheTest, HitReadsTheStoredFrame) {
  const synthetic::SyntheticSequence sequence = TinySequence(1);
  const synthetic::RenderedFrame rendered = RenderFrameCached(sequence, 0, dir_);
  for (const auto& entry : fs::directory_iterator(dir_)) {
    if (entry.path().extension() != ".frame") continue;
    std::fstream file(entry.path(), std::ios::in | std::ios::out | std::ios::binary);
    file.seekp(2 * sizeof(int32_t));  // the first image pixel, after rows and cols
    file.put(static_cast<char>(rendered.image.at<uint8_t>(0, 0) ^ 0xFF));
  }
  const synthetic::RenderedFrame hit = RenderFrameCached(sequence, 0, dir_);
  EXPECT_EQ(hit.image.at<uint8_t>(0, 0), rendered.image.at<uint8_t>(0, 0) ^ 0xFF);
  EXPECT_TRUE(SameBytes(hit.depth, rendered.depth));
}

// With the cache variable set, a sequence folder is written once, under the caller's folder name.
TEST_F(RenderCacheTest, SequenceFolderIsWrittenOnceUnderItsName) {
  synthetic::SynthOptions options = TinySequence(1).options;
  const char* saved = std::getenv("PLDVO_TEST_RENDER_CACHE");
  const std::string previous = saved == nullptr ? "" : saved;
  ::setenv("PLDVO_TEST_RENDER_CACHE", dir_.c_str(), 1);
  const fs::path first = SequenceFolderForTest(options, dir_ / "unused" / "tiny");
  const auto written = fs::last_write_time(first / "rgb.txt");
  const fs::path second = SequenceFolderForTest(options, dir_ / "unused" / "tiny");
  options.seed = 2;
  const fs::path other = SequenceFolderForTest(options, dir_ / "unused" / "tiny");
  ::setenv("PLDVO_TEST_RENDER_CACHE", previous.c_str(), 1);
  EXPECT_EQ(first.filename(), "tiny");
  EXPECT_EQ(first.parent_path().parent_path(), dir_);
  EXPECT_EQ(second, first);
  EXPECT_EQ(fs::last_write_time(second / "rgb.txt"), written);
  EXPECT_NE(other, first);
  EXPECT_TRUE(fs::exists(other / "rgb.txt"));
  EXPECT_FALSE(fs::exists(dir_ / "unused"));
}

}  // namespace
}  // namespace pldvo::test
