#include "record_track.hpp"

#include <stdexcept>
#include <utility>

#include "cli_registry.hpp"
#include "exit_status.hpp"
#include "pliant/vision/webcam_error.hpp"
#include "pliant/vision/webcam_frames.hpp"
#include "pliant/vision/webcam_recording.hpp"
#include "pliant/vision/webcam_tracker.hpp"
#include "progress_bar.hpp"

namespace pliant::cli {

namespace webcam = vision::webcam;

namespace {

class WebcamTracking final : public VideoTracking {
 public:
  explicit WebcamTracking(const TrackRequest& request);
  void check_frame_size(int width, int height) const override;
  host::Recording track(const std::string& video, const std::vector<double>& times_s, const std::string& name,
                        std::string& track_csv, bool progress) const override;

 private:
  webcam::Region region_;
  webcam::GridSpec grid_;
  webcam::TrackOptions options_;
};

WebcamTracking::WebcamTracking(const TrackRequest& request) {
  try {
    if (!request.roi.empty() && !request.mask.empty()) throw UsageError("give --roi or --mask, not both");
    if (!request.requested()) throw UsageError("tracking needs a region: --roi x,y,w,h or --mask PNG");
    webcam::TrackOptions& o = options_;
    o.flow = webcam::parse_flow_method(request.flow);
    o.support = webcam::parse_support(request.support);
    o.driven = webcam::parse_driven(request.driven);
    webcam::check_track_options(o);
    webcam::GridSpec grid;
    if (!request.grid.empty()) grid = webcam::parse_grid(request.grid);
    grid.spacing_px = request.spacing_px;
    if (request.grid.empty() && request.spacing_px == 0) grid = webcam::parse_grid("4x8");  // as `pliant track`
    grid_ = grid;
    region_ = request.roi.empty() ? webcam::read_mask(request.mask) : webcam::parse_roi(request.roi);
  } catch (const webcam::InputError& e) {
    throw UsageError(e.what());
  }
}

void WebcamTracking::check_frame_size(int width, int height) const {
  try {
    (void)webcam::seed_particles(region_, grid_, cv::Size(width, height));
  } catch (const webcam::InputError& e) {
    throw UsageError(std::string(e.what()) + " (first colour frame " + std::to_string(width) + "x" +
                     std::to_string(height) + ")");
  }
}

host::Recording WebcamTracking::track(const std::string& video, const std::vector<double>& times_s,
                                      const std::string& name, std::string& track_csv, bool progress) const {
  try {
    const auto source = webcam::open_frame_source(video, 0.0);
    webcam::FrameReader reader(*source, 0.0);
    webcam::TrackOptions options = options_;
    webcam::TrackResult result;
    {
      ProgressBar bar("tracking", progress);
      options.progress = &ProgressBar::callback;
      options.progress_context = &bar;
      result = webcam::track_particles(reader, region_, grid_, options);
    }
    for (int f = 0; f < result.frame_count(); ++f) {
      const int index = result.source_index[static_cast<std::size_t>(f)];
      if (index < 0 || static_cast<std::size_t>(index) >= times_s.size()) {
        throw std::runtime_error("the video has more frames than color_frames.csv (" + std::to_string(times_s.size()) +
                                 ")");
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

}  // namespace

void register_record_tracking(CliRegistry& registry) {
  registry.tracking = [](const TrackRequest& request) -> std::unique_ptr<VideoTracking> {
    return std::make_unique<WebcamTracking>(request);
  };
}

}  // namespace pliant::cli
