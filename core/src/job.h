// SPDX-License-Identifier: MIT
// One AO job: parameter values, attached images, and the run pipeline
// (frame -> variant -> denoise -> shaping -> outputs), each stage on tiles.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "camera_file.h"
#include "frame.h"
#include "image_view.h"
#include "params.h"
#include "temporal.h"
#include "tiles.h"

namespace ssao {

class Job {
 public:
  ParamValues& params() { return params_; }
  const ParamValues& params() const { return params_; }

  void set_image(const char* name, float* data, int width, int height, int channels,
                 std::ptrdiff_t pixel_stride, std::ptrdiff_t row_stride);
  void set_progress(Progress::Callback callback, void* user) {
    progress_callback_ = callback;
    progress_user_ = user;
  }
  // Overscan (ssao.h ssao_job_set_output_window): the outputs are the window of the input
  // images whose top-left pixel is (x, y).
  void set_output_window(bool enable, int x, int y);
  void run();
  // The automatic radius rule (docs/parameters.md) for the attached depth image and camera.
  double auto_radius() const;

  // The front ends' rules (ssao.h): a camera file's text sets the camera (all of it or none),
  // the radius when none was set, and what a run cannot tell from wrong.
  void set_camera_json(const std::string& text, const std::string& source);
  const CameraFile& camera_file() const { return camera_file_; }
  enum class RadiusSource { set = 0, camera_file = 1, automatic = 2 };
  RadiusSource choose_radius(bool allow_automatic);
  void check_inputs() const;

  // What the last successful run saw over the frame (the output window): the pixels the
  // background rule took as geometry and the mean of their final AO (1 without any).
  struct RunStats {
    size_t geometry_pixels = 0;
    double mean_ao = 1.0;
  };
  // Throws invalid_operation before a successful run.
  RunStats last_run() const;

 private:
  void validate_images() const;
  // The output window in input pixels: (x, y) and the outputs' size (the whole depth image
  // without a window, or while no output is attached).
  Tile output_window() const;
  // The camera of the input images: the parameters' camera (which describes the output
  // window, output_window()) moved to the window's place on the input's pixel grid.
  CameraModel input_camera(const Tile& window) const;

  TilePool& pool(int threads);

  ParamValues params_;
  // Kept between runs: the pool's threads start once, and the frame planes and the visibility
  // buffer (the library's only image-size buffers; with resolution = half, the half frame's
  // planes and a quarter-size visibility) are allocated once per image size.
  std::unique_ptr<TilePool> pool_;
  Frame frame_, half_frame_;
  std::vector<float> visibility_;
  // The frames before this one, for the temporal filter (temporal.h).
  TemporalHistory temporal_;
  // The slot an image name attaches to, nullptr for an unknown name.
  ImageView* image_slot(const char* name);
  // How many extra depth layers are attached (depth2, depth3, ... without a gap).
  int extra_layers() const;

  ImageView depth_, normal_, beauty_, edge_colours_, ambient_, ao_out_, composite_out_;
  ImageView layers_[kMaxExtraLayers], facing_[kMaxExtraLayers];
  CameraFile camera_file_;
  RunStats last_run_;
  bool has_run_ = false;
  bool windowed_ = false;
  int window_x_ = 0, window_y_ = 0;
  Progress::Callback progress_callback_ = nullptr;
  void* progress_user_ = nullptr;
};

}  // namespace ssao

// The C handle type is the job itself.
struct ssao_job_impl : ssao::Job {};
