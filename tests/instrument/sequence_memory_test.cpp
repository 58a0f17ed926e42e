// A measurement's memory estimated from its request, and the bound serve and measure
// refuse it beyond (sequence_memory.hpp), with the figures of the reproducers.
#include "piezoshift/instrument/sequence_memory.hpp"

#include <gtest/gtest.h>

#include <string>

#include "piezoshift/psi/frame_set.hpp"

namespace piezoshift::instrument {
namespace {

SequenceParams params(psi::Algorithm a, int averages) {
  SequenceParams p;
  p.steps_rad = commanded_steps(a, {}, "--algorithm");
  p.averages = averages;
  return p;
}

camera::CameraSettings camera_of(int side_px) {
  camera::CameraSettings c;
  c.width_px = side_px;
  c.height_px = side_px;
  return c;
}

// The estimate adds up what the measurement holds: 10 bytes a frame pixel, 25 an average's, 96
// of working set. 5 frames of 256 px: 65536 x (50 + 25 + 96) = 11 206 656 bytes.
TEST(SequenceMemory, TheEstimateCountsFramesAveragesAndTheWorkingSet) {
  EXPECT_EQ(sequence_memory_bytes(params(psi::Algorithm::kHariharan5, 1), camera_of(256)),
            11206656u);
  EXPECT_EQ(sequence_memory_bytes(params(psi::Algorithm::kHariharan5, 2), camera_of(256)) -
                sequence_memory_bytes(params(psi::Algorithm::kHariharan5, 1), camera_of(256)),
            65536u * (5 * kFrameBytesPerPixel + kAverageBytesPerPixel));
}

// The dashboard's reproducer: frame13 x 100 on 256 px frames (1300 frames, 1.09 GB in serve) is
// beyond psi's 2^26 frame pixels; 78 averages (1014 frames) are within, 79 are not.
TEST(SequenceMemory, Frame13WithAHundredAveragesIsRefusedNamingWhatFits) {
  const std::string why =
      sequence_memory_problem(params(psi::Algorithm::kFrame13, 100), camera_of(256));
  EXPECT_NE(why.find("100 averages x 13 frames of 256 x 256 px: 1300 frames"), std::string::npos)
      << why;
  EXPECT_NE(why.find("at most 78 averages on this camera"), std::string::npos) << why;
  EXPECT_EQ(sequence_memory_problem(params(psi::Algorithm::kFrame13, 78), camera_of(256)), "");
  EXPECT_NE(sequence_memory_problem(params(psi::Algorithm::kFrame13, 79), camera_of(256)), "");
  // The 512 px camera whose 100 averages ended serve in std::bad_alloc: 19 fit (247 frames).
  EXPECT_NE(sequence_memory_problem(params(psi::Algorithm::kFrame13, 100), camera_of(512))
                .find("at most 19 averages"),
            std::string::npos);
}

// `measure` on a 2048 px camera (350 MB an average before): the memory bound, not the frame
// count, limits hariharan5 to 2 averages (15 frames are within 2^26 pixels, 1.35 GB is not).
TEST(SequenceMemory, TheLargestCameraTakesWhatFitsInTheMemoryBound) {
  const camera::CameraSettings big = camera_of(2048);
  EXPECT_EQ(sequence_memory_problem(params(psi::Algorithm::kHariharan5, 2), big), "");
  const std::string why = sequence_memory_problem(params(psi::Algorithm::kHariharan5, 3), big);
  EXPECT_NE(why.find("at most 2 averages"), std::string::npos) << why;
  EXPECT_LE(15u * 2048u * 2048u, psi::kMaxFrameSetPixels);
  EXPECT_GT(sequence_memory_bytes(params(psi::Algorithm::kHariharan5, 3), big),
            kMaxSequenceMemoryBytes);
  // One average of frame13 fits (13 frames); nothing fits beyond it.
  EXPECT_EQ(sequence_memory_problem(params(psi::Algorithm::kFrame13, 1), big), "");
  EXPECT_NE(sequence_memory_problem(params(psi::Algorithm::kFrame13, 2), big)
                .find("at most 1 average on this camera"),
            std::string::npos);
}

}  // namespace
}  // namespace piezoshift::instrument
