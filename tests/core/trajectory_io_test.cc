#include "core/trajectory_io.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "core/random_draws.h"

namespace pldvo {
namespace {

using ::testing::HasSubstr;

class TrajectoryIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("pldvo_trajectory_io_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::string Write(const std::string& name, const std::string& text) {
    const std::string path = (dir_ / name).string();
    std::ofstream(path) << text;
    return path;
  }

  // The message of the runtime_error ReadTrajectoryTum throws, or "" if none.
  std::string ReadError(const std::string& path) {
    try {
      ReadTrajectoryTum(path);
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    return "";
  }

  std::filesystem::path dir_;
};

TEST_F(TrajectoryIoTest, WriteThenReadIsExact) {
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  Trajectory trajectory;
  for (int i = 0; i < 50; ++i) {
    StampedPose pose;
    pose.timestamp = 1305031102.175304 + 0.0333 * i;  // TUM-like absolute times
    const Eigen::Vector3d t = DrawVector3(normal, rng);
    const double qz = normal(rng), qy = normal(rng), qx = normal(rng), qw = normal(rng);
    pose.world_from_cam = SE3(Eigen::Quaterniond(qw, qx, qy, qz).normalized(), t);
    trajectory.push_back(pose);
  }
  const std::string path = (dir_ / "traj.txt").string();
  WriteTrajectoryTum(trajectory, path);
  const Trajectory read = ReadTrajectoryTum(path);
  ASSERT_EQ(read.size(), trajectory.size());
  for (size_t i = 0; i < read.size(); ++i) {
    // 17 significant digits round-trip doubles exactly; the quaternion is re-normalised on
    // reading, which may change its last bit.
    EXPECT_EQ(read[i].timestamp, trajectory[i].timestamp);
    EXPECT_EQ(read[i].world_from_cam.translation(), trajectory[i].world_from_cam.translation());
    EXPECT_LT((read[i].world_from_cam.rotation().coeffs() -
               trajectory[i].world_from_cam.rotation().coeffs())
                  .norm(),
              1e-15);
  }
}

TEST_F(TrajectoryIoTest, SkipsCommentsBlankLinesAndCarriageReturns) {
  const Trajectory read = ReadTrajectoryTum(Write("t.txt",
                                                  "# timestamp tx ty tz qx qy qz qw\n"
                                                  "\n"
                                                  "1.0 1 2 3 0 0 0 1\r\n"
                                                  "   # indented comment\n"
                                                  "2.5\t4 5 6 0 0 1 0\n"));
  ASSERT_EQ(read.size(), 2u);
  EXPECT_EQ(read[0].timestamp, 1.0);
  EXPECT_EQ(read[0].world_from_cam.translation(), Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(read[1].timestamp, 2.5);
  // qz = 1: a rotation of pi about z.
  EXPECT_NEAR(read[1].world_from_cam.rotation_matrix()(0, 0), -1.0, 1e-15);
}

TEST_F(TrajectoryIoTest, WriteTumLineKeepsTheStreamPrecision) {
  std::ostringstream out;
  out.precision(3);
  StampedPose pose;
  pose.timestamp = 0.123456789012;
  WriteTumLine(pose, out);
  EXPECT_THAT(out.str(), HasSubstr("0.123456789012"));
  EXPECT_EQ(out.precision(), 3);
}

TEST_F(TrajectoryIoTest, MissingFileIsAnErrorNamingIt) {
  const std::string path = (dir_ / "none.txt").string();
  EXPECT_THAT(ReadError(path), HasSubstr(path));
}

TEST_F(TrajectoryIoTest, WrongFieldCountNamesFileAndLine) {
  const std::string path = Write("t.txt", "1 0 0 0 0 0 0 1\n# c\n2 0 0 0 0 0 1\n");
  EXPECT_THAT(ReadError(path), HasSubstr(path + ":3: expected 8 fields"));
}

TEST_F(TrajectoryIoTest, NonNumericNamesFileAndLine) {
  const std::string path = Write("t.txt", "1 0 0 0 0 0 0 1\n2 0 0 x 0 0 0 1\n");
  EXPECT_THAT(ReadError(path), HasSubstr(path + ":2: 'x' is not a number"));
  const std::string trailing = Write("u.txt", "1 0 0 0 0 0 0 1abc\n");
  EXPECT_THAT(ReadError(trailing), HasSubstr(trailing + ":1:"));
}

TEST_F(TrajectoryIoTest, NanAndInfAreErrors) {
  const std::string nan_path = Write("nan.txt", "1 nan 0 0 0 0 0 1\n");
  EXPECT_THAT(ReadError(nan_path), HasSubstr(nan_path + ":1: 'nan' is not a finite number"));
  const std::string inf_path = Write("inf.txt", "1 0 0 0 0 0 0 1\n2 0 -inf 0 0 0 0 1\n");
  EXPECT_THAT(ReadError(inf_path), HasSubstr(inf_path + ":2: '-inf' is not a finite number"));
}

TEST_F(TrajectoryIoTest, NonUnitQuaternionIsAnError) {
  const std::string path = Write("t.txt", "1 0 0 0 0 0 0 1\n2 0 0 0 0 0 0 2\n");
  EXPECT_THAT(ReadError(path), HasSubstr(path + ":2: quaternion"));
  // A quaternion printed with 4 decimals is within 1e-4 of unit norm and is accepted.
  EXPECT_EQ(ReadTrajectoryTum(Write("ok.txt", "1 0 0 0 0.7071 0 0 0.7071\n")).size(), 1u);
}

TEST_F(TrajectoryIoTest, NonIncreasingTimestampsAreErrors) {
  const std::string equal = Write("eq.txt", "1 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n");
  EXPECT_THAT(ReadError(equal), HasSubstr(equal + ":2: timestamp 1 does not increase"));
  const std::string back =
      Write("back.txt", "1 0 0 0 0 0 0 1\n2 0 0 0 0 0 0 1\n1.5 0 0 0 0 0 0 1\n");
  EXPECT_THAT(ReadError(back), HasSubstr(back + ":3: timestamp 1.5 does not increase"));
}

}  // namespace
}  // namespace pldvo
