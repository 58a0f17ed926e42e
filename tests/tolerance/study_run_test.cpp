// A study as one runs it: the description a Dask worker is handed rebuilds the same study and the
// same sample; records resume only their own study; the report says the same in Markdown and HTML.
#include "piezoshift/tolerance/study_run.hpp"

#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "piezoshift/core/input_error.hpp"
#include "temp_dir_test.hpp"
#include "test_paths.hpp"

namespace piezoshift::tolerance {
namespace {

StudyInputs paper_stage(std::uint64_t seed) {
  StudyInputs in;
  in.tolerances = testing::source_dir() + "/configs/tolerances/paper_stage.toml";
  in.config = testing::source_dir() + "/configs/paper.toml";
  in.samples = 8;
  in.options.seed = seed;
  return in;
}

TEST(StudyRun, ADescriptionRebuildsTheStudyAndTheSampleAWorkerRuns) {
  const Study s = load_study(paper_stage(5));
  // Through text, as it crosses to a worker.
  const Study w = study_from_description(nlohmann::json::parse(description(s).dump()));
  EXPECT_EQ(w.header, s.header);
  EXPECT_EQ(w.samples, 8U);
  ASSERT_EQ(w.set.tolerances.size(), s.set.tolerances.size());
  EXPECT_EQ(w.set.tolerances[0].nominal, s.set.tolerances[0].nominal);
  // The sample the worker returns is the bytes a local thread records.
  EXPECT_EQ(sample_json(w.set, run_study_sample(w, 2)).dump(),
            sample_json(s.set, run_study_sample(s, 2)).dump());
  try {
    study_from_description(nlohmann::json{{"seed", 1}});
    FAIL() << "a description without its files was taken";
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("description"), std::string::npos) << e.what();
  }
}

class StudyFiles : public testing::TempDirTest {};

SampleResult fake_sample(const Study& s, std::uint64_t index, double first_mode_Hz) {
  SampleResult r;
  r.index = index;
  r.deviations.assign(s.set.tolerances.size(), 0.0);
  r.metrics.assign(metrics().size(), std::nan(""));
  r.metrics[0] = first_mode_Hz;
  r.compensators.assign(compensators().size(), std::nan(""));
  return r;
}

TEST_F(StudyFiles, ARecordResumesOnlyItsOwnStudy) {
  const Study s = load_study(paper_stage(5));
  record_sample(s, dir_, fake_sample(s, 3, 1800.25));
  const std::optional<SampleResult> back = resumed_sample(s, dir_, 3);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->metrics[0], 1800.25);
  EXPECT_FALSE(resumed_sample(s, dir_, 4).has_value());                           // never run
  EXPECT_FALSE(resumed_sample(load_study(paper_stage(6)), dir_, 3).has_value());  // another seed
}

TEST_F(StudyFiles, TheReportIsMarkdownAndHtmlThatSayTheSame) {
  StudyInputs in = paper_stage(5);
  in.spec = write("spec.toml", "[spec]\nfirst_mode_Hz_min = 1800\n");
  in.samples = 2;
  const Study s = load_study(in);
  const StudyOutputs o = write_study_outputs(
      s, {fake_sample(s, 0, 1790.0), fake_sample(s, 1, 1850.0)}, dir_, false, std::nullopt);
  EXPECT_EQ(o.samples, 2U);
  EXPECT_EQ(o.pass, 1U);
  EXPECT_DOUBLE_EQ(o.fraction, 0.5);
  const std::string md = read_text(o.markdown.string()), html = read_text(o.html.string());
  const std::string yield = "1 of 2 samples meet the spec (50.0 %); 2 valid.";
  EXPECT_NE(md.find(yield), std::string::npos) << md;
  EXPECT_NE(html.find(yield), std::string::npos) << html;
  EXPECT_NE(html.find("<table>"), std::string::npos);
  EXPECT_NE(md.find("first_mode_Hz = 1790 < 1800"), std::string::npos) << md;
}

}  // namespace
}  // namespace piezoshift::tolerance
