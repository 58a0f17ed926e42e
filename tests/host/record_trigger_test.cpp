// The data recorder's trigger (DRT) on its own: which events restart a recording, for which
// source, and from which command's samples on the recording takes points.
#include <gtest/gtest.h>

#include "piezoshift/host/record_trigger.hpp"

namespace piezoshift::host {
namespace {

class RecordTriggerTest : public ::testing::Test {
 protected:
  void record(int n) {
    for (int i = 0; i < n; ++i)
      recorder_.record(RecorderInput{});
  }

  DataRecorder recorder_;
  RecordTrigger trigger_{recorder_};
};

TEST_F(RecordTriggerTest, SourcesAreThoseDrtAccepts) {
  for (long long s : {0, 1, 2, 4})
    EXPECT_TRUE(RecordTrigger::is_source(s)) << s;
  for (long long s : {-1, 3, 5, 0x101})
    EXPECT_FALSE(RecordTrigger::is_source(s)) << s;
  EXPECT_EQ(trigger_.source(), 0);  // the default: motion commands
}

TEST_F(RecordTriggerTest, MotionRestartsWithSources0And1FromTheCommandsSamplesOn) {
  record(3);
  EXPECT_EQ(recorder_.points(), 3u);
  trigger_.motion(5);
  EXPECT_EQ(recorder_.points(), 0u);
  EXPECT_FALSE(trigger_.records(4));  // a tick from before the loop applied command 5
  EXPECT_TRUE(trigger_.records(5));
  trigger_.set_source(1, 5);
  record(2);
  trigger_.motion(6);
  EXPECT_EQ(recorder_.points(), 0u);
  EXPECT_FALSE(trigger_.records(5));
}

TEST_F(RecordTriggerTest, Source4RestartsAtTheDrtAndIgnoresMotion) {
  trigger_.motion(2);
  record(4);
  trigger_.set_source(4, 3);
  EXPECT_EQ(recorder_.points(), 0u);
  EXPECT_FALSE(trigger_.records(2));
  record(2);
  trigger_.motion(7);
  EXPECT_EQ(recorder_.points(), 2u);
  EXPECT_TRUE(trigger_.records(3));  // still from the DRT's command on
  EXPECT_EQ(trigger_.source(), 4);
}

TEST_F(RecordTriggerTest, Source2RestartsAtTheNextLineThenIsTheDefaultAgain) {
  trigger_.set_source(2, 3);
  record(2);
  trigger_.line_done("DRT", 3);  // the DRT that set it is not "the next command"
  EXPECT_EQ(recorder_.points(), 2u);
  EXPECT_EQ(trigger_.source(), 2);
  trigger_.line_done("POS?", 4);
  EXPECT_EQ(recorder_.points(), 0u);
  EXPECT_EQ(trigger_.source(), 0);
  EXPECT_FALSE(trigger_.records(3));
  EXPECT_TRUE(trigger_.records(4));
  record(3);
  trigger_.line_done("POS?", 4);  // source 0: a line restarts nothing
  EXPECT_EQ(recorder_.points(), 3u);
}

TEST_F(RecordTriggerTest, RestartIsUnconditional) {
  trigger_.set_source(4, 0);
  record(5);
  trigger_.restart(9);  // WGR
  EXPECT_EQ(recorder_.points(), 0u);
  EXPECT_FALSE(trigger_.records(8));
  EXPECT_TRUE(trigger_.records(9));
}

}  // namespace
}  // namespace piezoshift::host
