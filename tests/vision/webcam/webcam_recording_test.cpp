// A tracked video as a recording: what particles.csv holds, track.csv, and the atomic write.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "pliant/host/recording.hpp"
#include "pliant/vision/webcam_error.hpp"
#include "pliant/vision/webcam_recording.hpp"
#include "webcam_test_support.hpp"

namespace pliant::vision::webcam {
namespace {

using test::TempDir;
namespace fs = std::filesystem;

// Two frames of a 2 x 2 grid: particle 1 unobserved in frame 1, particle 3 (driven) too.
TrackResult small_result() {
  TrackResult r;
  r.source = "clip.avi";
  r.frame_size = cv::Size(64, 48);
  r.source_fps_hz = 30;
  r.rate_hz = 30;
  r.grid = seed_particles(parse_roi("0,0,40,40"), parse_grid("2x2"), r.frame_size);
  r.times_s = {0.0, 1.0 / 30};
  r.source_index = {0, 1};
  for (int f = 0; f < 2; ++f) {
    for (int i = 0; i < 4; ++i) {
      r.tracked.push_back(r.grid.positions[static_cast<std::size_t>(i)] + cv::Point2d(0, 0.5 * f));
      const bool used = f == 0 || (i != 1 && i != 3);
      r.observed.push_back(used ? 1 : 0);
      r.check.push_back(static_cast<std::uint8_t>(used ? ObservationKind::advected : ObservationKind::dissimilar));
      r.status.push_back(static_cast<std::uint8_t>(used ? TrackStatus::observed : TrackStatus::predicted));
      r.fb_error_px.push_back(0.01f);
      r.similarity.push_back(used ? 0.99f : 0.3f);
    }
  }
  r.motion_px.assign(4, 0.5);
  r.roles.support = {0};
  r.roles.driven = 3;
  return r;
}

TEST(webcam_recording, ParticlesHoldObservationsAndTheDrivenPath) {
  const TrackResult r = small_result();
  const host::Recording rec = track_recording(r, "clip");
  EXPECT_EQ(rec.name, "clip");
  EXPECT_EQ(rec.dimension, 2);
  EXPECT_EQ(rec.length_unit, "px");
  EXPECT_FALSE(rec.gravity.has_value());
  EXPECT_EQ(rec.particle_count, 4);
  EXPECT_EQ(rec.fixed, (std::vector<int>{0}));
  ASSERT_EQ(rec.driven.size(), 1u);
  EXPECT_EQ(rec.driven[0].id, 3);
  EXPECT_TRUE(std::isinf(rec.driven[0].from_s) && std::isinf(rec.driven[0].to_s));
  EXPECT_EQ(rec.files.at("track"), "track.csv");
  EXPECT_FALSE(rec.observed(1, 1));  // unobserved: absent
  EXPECT_TRUE(rec.observed(1, 3));   // driven: its tracked path is always there
  EXPECT_DOUBLE_EQ(rec.position(1, 3, 1), r.tracked[r.at(1, 3)].y);
  EXPECT_EQ(rec.meta.at("track").at("flow"), "dis");
  EXPECT_EQ(rec.meta.at("track").at("unobserved_particle_frames"), 2);
  EXPECT_EQ(rec.meta.at("camera"), "64x48 @ 30 Hz");

  const std::string csv = track_csv_text(r);
  EXPECT_EQ(csv.rfind("t,id,x,y,observed,status,check,fb_error_px,similarity\n", 0), 0u);
  EXPECT_NE(csv.find("\n0.03333333333333333,1,29.5,10,0,predicted,dissimilar,0.01,0.3\n"), std::string::npos) << csv;
}

TEST(webcam_recording, WriteIsAtomicAndReadsBack) {
  TempDir dir;
  const TrackResult r = small_result();
  const std::string out = dir / "rec";
  write_track_recording(r, out);
  const host::Recording back = host::read_recording(out);
  EXPECT_EQ(back.length_unit, "px");
  EXPECT_EQ(back.frame_count(), 2);
  EXPECT_EQ(back.fixed, (std::vector<int>{0}));
  EXPECT_FALSE(back.observed(1, 1));
  EXPECT_NEAR(back.position(1, 2, 1), r.tracked[r.at(1, 2)].y, 1e-12);
  EXPECT_TRUE(fs::exists(fs::path(out) / "track.csv"));
  // Only the recording is left: no temporary directory beside it.
  int entries = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir.path())) ++entries;
  EXPECT_EQ(entries, 1);

  // A non-empty target is refused before anything is written; an empty one is used.
  EXPECT_THROW(write_track_recording(r, out), InputError);
  EXPECT_THROW(check_output_directory(out), InputError);
  test::write_bytes(dir / "file", "x");
  EXPECT_THROW(check_output_directory(dir / "file"), InputError);
  fs::create_directory(dir / "empty");
  write_track_recording(r, dir / "empty/");
  EXPECT_EQ(host::read_recording(dir / "empty").particle_count, 4);

  // A failure while writing (the parent is a file) leaves nothing behind.
  EXPECT_THROW(write_track_recording(r, dir / "file/rec"), std::runtime_error);
  EXPECT_FALSE(fs::exists(dir / "file.pliant-tmp"));
  int after = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir.path())) ++after;
  EXPECT_EQ(after, 3);  // rec, file, empty
}

TEST(webcam_recording, TrackedTranslationEndToEnd) {
  // A texture sliding down 0.5 px per frame: every particle moves alike, roles given.
  const cv::Mat texture = test::random_texture(96, 72, 9);
  std::vector<cv::Mat> frames;
  for (int k = 0; k < 6; ++k) frames.push_back(test::shifted(texture, 0, 0.5 * k));
  MemoryFrameSource source(frames, 10, "slide");
  FrameReader reader(source, 0);
  TrackOptions options;
  options.support = parse_support("bottom");
  options.driven = parse_driven("1");
  int last_done = 0;
  options.progress = [](void* context, int done, int total) {
    EXPECT_EQ(total, 6);
    *static_cast<int*>(context) = done;
  };
  options.progress_context = &last_done;
  const TrackResult r = track_particles(reader, parse_roi("16,12,64,48"), parse_grid("3x4"), options);
  EXPECT_EQ(last_done, 6);
  ASSERT_EQ(r.frame_count(), 6);
  EXPECT_DOUBLE_EQ(r.times_s[5], 0.5);
  EXPECT_EQ(r.options.advection.dis_finest_scale, 0);  // 16 px spacing
  for (int i = 0; i < r.particle_count(); ++i) {
    const cv::Point2d d = r.tracked[r.at(5, i)] - r.grid.positions[static_cast<std::size_t>(i)];
    EXPECT_NEAR(d.x, 0, 0.15) << i;
    EXPECT_NEAR(d.y, 2.5, 0.15) << i;
    EXPECT_EQ(r.observed[r.at(5, i)], 1) << i;
  }
  EXPECT_EQ(r.roles.support, (std::vector<int>{8, 9, 10, 11}));
  EXPECT_EQ(r.roles.driven, 1);

  // Resampled to 5 Hz: every other frame.
  MemoryFrameSource again(frames, 10, "slide");
  FrameReader half(again, 5);
  options.progress = nullptr;
  EXPECT_EQ(track_particles(half, parse_roi("16,12,64,48"), parse_grid("3x4"), options).frame_count(), 3);

  // One frame only, or nothing moving while roles are to be detected: refused.
  MemoryFrameSource single({texture}, 10);
  FrameReader single_reader(single, 0);
  EXPECT_THROW(track_particles(single_reader, parse_roi("16,12,64,48"), parse_grid("3x4"), options), InputError);
  MemoryFrameSource still({texture, texture, texture}, 10);
  FrameReader still_reader(still, 0);
  EXPECT_THROW(track_particles(still_reader, parse_roi("16,12,64,48"), parse_grid("3x4"), TrackOptions{}), InputError);
  MemoryFrameSource none({}, 10);
  FrameReader none_reader(none, 0);
  EXPECT_THROW(track_particles(none_reader, parse_roi("16,12,64,48"), parse_grid("3x4"), options), InputError);
  TrackOptions bad = options;
  bad.tracker_msm_beta = 1.5;
  MemoryFrameSource any(frames, 10);
  FrameReader any_reader(any, 0);
  EXPECT_THROW(track_particles(any_reader, parse_roi("16,12,64,48"), parse_grid("3x4"), bad), InputError);
}

}  // namespace
}  // namespace pliant::vision::webcam
