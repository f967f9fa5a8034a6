#include "record_track.hpp"

#include <stdexcept>
#include <utility>

#include "exit_status.hpp"
#include "progress_bar.hpp"
#include "pliant/vision/webcam_error.hpp"
#include "pliant/vision/webcam_frames.hpp"
#include "pliant/vision/webcam_recording.hpp"
#include "pliant/vision/webcam_tracker.hpp"

namespace pliant::cli {

namespace webcam = vision::webcam;

struct VideoTracking::Impl {
  webcam::Region region;
  webcam::GridSpec grid;
  webcam::TrackOptions options;
};

VideoTracking::VideoTracking(const TrackRequest& request) : impl_(std::make_unique<Impl>()) {
  try {
    if (!request.roi.empty() && !request.mask.empty()) throw UsageError("give --roi or --mask, not both");
    if (!request.requested()) throw UsageError("tracking needs a region: --roi x,y,w,h or --mask PNG");
    webcam::TrackOptions& o = impl_->options;
    o.flow = webcam::parse_flow_method(request.flow);
    o.support = webcam::parse_support(request.support);
    o.driven = webcam::parse_driven(request.driven);
    webcam::check_track_options(o);
    webcam::GridSpec grid;
    if (!request.grid.empty()) grid = webcam::parse_grid(request.grid);
    grid.spacing_px = request.spacing_px;
    if (request.grid.empty() && request.spacing_px == 0) grid = webcam::parse_grid("4x8");  // as `pliant track`
    impl_->grid = grid;
    impl_->region = request.roi.empty() ? webcam::read_mask(request.mask) : webcam::parse_roi(request.roi);
  } catch (const webcam::InputError& e) {
    throw UsageError(e.what());
  }
}

VideoTracking::~VideoTracking() = default;

void VideoTracking::check_frame_size(int width, int height) const {
  try {
    (void)webcam::seed_particles(impl_->region, impl_->grid, cv::Size(width, height));
  } catch (const webcam::InputError& e) {
    throw UsageError(std::string(e.what()) + " (first colour frame " + std::to_string(width) + "x" +
                     std::to_string(height) + ")");
  }
}

host::Recording VideoTracking::track(const std::string& video, const std::vector<double>& times_s,
                                     const std::string& name, std::string& track_csv, bool progress) const {
  try {
    const auto source = webcam::open_frame_source(video, 0.0);
    webcam::FrameReader reader(*source, 0.0);
    webcam::TrackOptions options = impl_->options;
    webcam::TrackResult result;
    {
      ProgressBar bar("tracking", progress);
      options.progress = &ProgressBar::callback;
      options.progress_context = &bar;
      result = webcam::track_particles(reader, impl_->region, impl_->grid, options);
    }
    for (int f = 0; f < result.frame_count(); ++f) {
      const int index = result.source_index[static_cast<std::size_t>(f)];
      if (index < 0 || static_cast<std::size_t>(index) >= times_s.size()) {
        throw std::runtime_error("the video has more frames than color_frames.csv (" +
                                 std::to_string(times_s.size()) + ")");
      }
      result.times_s[static_cast<std::size_t>(f)] = times_s[static_cast<std::size_t>(index)];
    }
    host::Recording recording = webcam::track_recording(result, name);
    track_csv = webcam::track_csv_text(result);
    return recording;
  } catch (const webcam::InputError& e) {
    throw std::runtime_error(std::string("tracking the recorded colour video: ") + e.what());
  } catch (const host::RecordingError& e) {
    throw std::runtime_error(std::string("tracking the recorded colour video: ") + e.what());
  }
}

}  // namespace pliant::cli
