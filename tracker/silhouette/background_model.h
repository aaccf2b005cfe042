#pragma once
// Background subtraction (thesis 3.1): a per-pixel Gaussian learnt from
// empty-stage frames, then dilations/erosions and small-blob removal.
//
// Two models:
//  - "plain": the thesis's — mean μ and standard deviation σ per pixel; a pixel
//    is foreground when |I − μ| / σ exceeds the threshold.
//  - "flicker" (default): the screen's light changes the whole stage's
//    brightness from frame to frame, so each pixel is modelled as
//    μ(t) = a + b·L(t), L the frame's light level (the mean empty-stage
//    intensity off the screens), with a, b by least squares over the training
//    frames and σ the residual. The slope b is smoothed over a few pixels
//    (`slope_sigma`): the screens' light falls smoothly on the stage, and one
//    pixel's slope over a dozen frames is mostly noise. At run time L(t) is
//    found from the frame itself — the median over well-lit pixels of
//    (I − a) / b, robust to the person covering a minority of them — and
//    pixels are tested against a + b·L(t). With no light change in the
//    training frames (a short capture between screen cuts) each pixel is
//    taken to scale with the light: a = 0, b = μ / mean(L). Empty-stage
//    frames filmed while the screens sweep their brightness (what `irbench
//    render` writes) let b learn how much of each pixel's light is the
//    screens': a screen flash brightens the floor before the screen, not
//    the back wall.
//    Screen pixels (seen on a projection screen) follow the same model on the
//    screen's own level G(t) (the mean of the screen pixels; a per-pixel
//    offset and slope, as the sensor's black level and tone curve make them),
//    read from the frame by the same median.
//    The normalised difference z = (I − μ(t)) / σ is also pooled over a small
//    Gaussian window, whose noise (measured on the training frames) is several
//    times lower than a pixel's: clothing only a few grey levels off the wall
//    behind it is found; pixels above the per-pixel threshold are kept too.
//    The outline is then moved to the blurred edge's inflection (the sign of
//    the smoothed difference's Laplacian): the lens's blur lifts the pixels
//    around the body over the thresholds, and the silhouette grew by a pixel
//    all round.

#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace irbench {

// Which background model segments the frames: the per-pixel light-following
// model (flicker) or the thesis's per-pixel Gaussian (plain, 3.1).
enum class BackgroundKind { kFlicker, kPlain };
// "flicker" / "plain"; nullopt for another name.
std::optional<BackgroundKind> ParseBackgroundKind(const std::string& name);
const char* BackgroundKindName(BackgroundKind kind);

struct BackgroundOptions {
  BackgroundKind model = BackgroundKind::kFlicker;
  double threshold_sigma = 4.0;   // |I − μ| / σ above this: foreground
  double min_sigma = 2.0;         // grey levels; floors σ (8-bit quantisation, few frames)
  // Morphology, in pixels at 320x240 (scaled with the image width): an opening
  // removes specks, a closing fills pinholes and smooths the boundary. With
  // the outline refinement on (below) there is no opening: the refinement
  // decides the outline's pixels, spurs included, by the edge (the opening
  // took off thin parts with them: thesis preset IoU 0.870 with it, 0.877
  // without, before the refinement filled its holes).
  int open_radius = 1;
  int close_radius = 2;
  // Flicker model: the pooling window (Gaussian sigma, px at 320x240; 0: off)
  // and the threshold on the pooled difference, in units of its own noise —
  // measured on the empty-stage frames, and no lower than 8-bit rounding
  // alone makes it (1/√12 grey levels a pixel): empty-stage frames without
  // noise (the `clean` preset) would put the thresholds at nothing, and the
  // faintest tail of a blurred outline would join the body.
  double pool_sigma = 0.8;
  double pool_threshold = 6.0;
  double pool_weak_threshold = 3.0;  // hysteresis: weaker evidence joined to strong
  // Flicker model: the Gaussian (sigma, px at 320x240) the per-pixel slopes b
  // are smoothed with; 0: each pixel's own. Their noise, over which a pixel
  // must rise to read L from, is scaled by the whole kernel's norm (near the
  // image's border and the screens, where fewer pixels are averaged, it is
  // underestimated: a few more pixels pass there).
  double slope_sigma = 2.0;
  // Connected blobs smaller than this fraction of the image are noise,
  // unless they lie within `near_blob_px` (at 320x240) of a blob kept by
  // area and hold at least `near_blob_min_fraction`: a forearm or hand cut
  // off from the body by a low-contrast gap (an upper arm seen end-on) is a
  // part of the person, not a speck.
  double min_blob_fraction = 0.002;
  double near_blob_px = 10;
  double near_blob_min_fraction = 0.0003;
  // Outline refinement (flicker model): the lens blurs the body's outline
  // over a few pixels, and the pooled evidence finds the blur's faint tail,
  // so the silhouette grows a pixel all round. The outline is moved towards
  // the blurred edge's inflection, where the Laplacian of the smoothed
  // difference I − μ(t) (grey levels, Gaussian of `outline_sigma` px at
  // 320x240) changes sign: a pixel is inside where the Laplacian bends away
  // from the stage's level. Decided so: the pixels within `outline_band` px
  // of the outline, and those inside whose smoothed difference is under
  // `outline_doubt` times its noise (foreground only the pooling found, gaps
  // the closing filled). Pixels whose Laplacian is under
  // `outline_min_laplacian` times its noise keep their label (both noises
  // measured on the empty-stage frames, one figure per image, and no lower
  // than 8-bit rounding alone makes them: see `pool_threshold`). Holes this
  // opens inside the mask of up to `outline_max_hole` pixels (at 320x240)
  // are noise and filled; parts it cuts off go by the blob rules above. One
  // pass: where the mask was two pixels too wide, it stays one too wide
  // (straight blurred edges in background_model_test). 0 sigma: off.
  double outline_sigma = 0.8;
  int outline_band = 1;
  double outline_min_laplacian = 2.5;
  double outline_doubt = 16;
  double outline_max_hole = 8;
  // Throws InputError naming the option.
  void Check() const;  // throws InputError naming the field
};

struct SilhouetteResult {
  cv::Mat mask;            // CV_8UC1, 255 foreground
  cv::Mat raw;             // before morphology and blob removal
  cv::Mat darker;          // 255 where the frame is darker than the expected stage (smoothed),
                           // within `mask`'s rows (0 elsewhere: shadow removal reads no more)
  double light_level = 0;  // L(t) (flicker model); the training mean for "plain"
  double screen_gain = 1;  // the screen's level G(t) relative to its training mean
  int blobs_removed = 0;
};

class BackgroundModel {
 public:
  // Learns the model from empty-stage frames (8-bit, one channel, same size).
  // `screen` (optional, CV_8U, 255 where the camera sees a projection screen):
  // those pixels change with the projected content, not with the stage's
  // light; in the flicker model they follow the screen's own level G, read
  // per frame as the median over the screen pixels (robust to a person
  // covering fewer than half of them). nullopt when there are no frames or
  // they differ in size.
  static std::optional<BackgroundModel> Train(const std::vector<cv::Mat>& frames,
                                              const BackgroundOptions& options,
                                              const cv::Mat& screen = cv::Mat());

  SilhouetteResult Segment(const cv::Mat& frame) const;

  const BackgroundOptions& options() const { return options_; }
  // Per-pixel model (CV_32F): the expected intensity at light level L is
  // a + b·L, with residual σ; at screen pixels (flicker model with a screen)
  // a + b·G, G the screen's level (screen_gain times its training mean).
  const cv::Mat& a() const { return a_; }
  const cv::Mat& b() const { return b_; }
  const cv::Mat& sigma() const { return sigma_; }
  // Pixels L(t) is read from (0 for the plain model: L is the training mean).
  int light_pixel_count() const { return light_pixel_count_; }
  double mean_light() const { return mean_light_; }
  // The expected empty-stage image at light level `light` (screen pixels
  // excepted: they follow the screen's level, not L).
  cv::Mat Expected(double light) const;
  // L(t) estimated from `frame` (the training mean for "plain").
  double EstimateLight(const cv::Mat& frame) const;

 private:
  BackgroundOptions options_;
  cv::Mat a_, b_, sigma_;
  // z = (I − μ(t)) / σ, CV_32F; screen pixels: (I − (a + b·g·Ḡ)) / (max(g, 1)·σ),
  // g the screen gain and Ḡ the screen's mean level in training.
  cv::Mat Normalised(const cv::Mat& frame, float light, float screen_gain) const;
  double EstimateScreenGain(const cv::Mat& frame) const;
  double PoolSigmaPx(int width) const { return options_.pool_sigma * width / 320.0; }

  int light_pixel_count_ = 0;  // pixels whose b is large enough to read L from
  std::vector<std::pair<int, int>> light_samples_;  // (y, x): those on even rows and columns
  std::vector<float> light_a_, light_b_;             // a_ and b_ there, in the same order
  cv::Mat screen_;        // CV_8U: screen pixels (may be empty)
  double mean_screen_ = 0;  // the screen pixels' mean level G over the training frames
  // The pixels G is read from, on even rows and columns, with a and b there.
  std::vector<std::pair<int, int>> screen_samples_;
  std::vector<float> screen_a_, screen_b_;
  double mean_light_ = 0;
  double pooled_noise_ = 1;  // std of the pooled z on the training frames
  // On the training frames, grey levels: the rms of I − μ(t) smoothed by
  // outline_sigma, and of that smoothed difference's Laplacian.
  double smoothed_noise_ = 1;
  double outline_noise_ = 1;
  double OutlineSigmaPx(int width) const { return options_.outline_sigma * width / 320.0; }
  // Moves `mask`'s outline to the inflection of the blurred edge (see
  // BackgroundOptions::outline_sigma).
  void RefineOutline(const cv::Mat& z, cv::Mat& mask) const;

  // Train's steps (background_model.cc), on the training frames' statistics.
  struct TrainingSet;
  // Fits a, b and σ per pixel on the light level L (b by regression, or each
  // pixel scaling with L) and picks the pixels L is read from (those that
  // follow it clearly: b well above its noise), screen pixels excepted, into
  // `light_pixels` (CV_8U). Returns the residual's degrees of freedom.
  int FitLight(const TrainingSet& set, bool by_regression, cv::Mat& light_pixels);
  // The screen pixels: the same model on the screen's own level G (the mean
  // of its pixels; see the header), fitted over the training frames where G
  // changes (a calibration sweep), else each pixel scales with it; so too
  // when the regression leaves too few pixels to read G from (a change in
  // training too small for the noise). Fills `screen_level` with G per
  // frame, or -1 for all when G is to be read from the frames.
  void FitScreen(const TrainingSet& set, std::vector<double>& screen_level);
  // Fits the screen pixels' lines on G (`screen_level` per frame, mean
  // `g_mean`, variance `g_var`, `sum_g` = Σ I·(G − Ḡ)) and picks the pixels G
  // is read from; false when too few are.
  bool FitScreenLines(const TrainingSet& set,
                      const std::vector<double>& screen_level,
                      double g_mean,
                      double g_var,
                      const cv::Mat& sum_g,
                      bool by_regression);
  // Keeps the pixels of `light_pixels` on even rows and columns, with a and b
  // there, as the samples L is read from.
  void SampleLightPixels(const cv::Mat& light_pixels);
  // The noises the thresholds are set in, measured on the training frames:
  // the pooled z's, and the outline refinement's (the difference I − μ(t)
  // in grey levels smoothed by its Gaussian, and that smoothed difference's
  // Laplacian), each one figure for the whole image. `regress`: L was
  // regressed; `dof`: the light lines' degrees of freedom; `screen_level`:
  // G per frame (-1: read from the frame).
  void MeasureTrainingNoise(const TrainingSet& set,
                            bool regress,
                            int dof,
                            const std::vector<double>& screen_level);
};

// The value of rank `k` (< v.size()) in `v`: what std::nth_element puts at
// v[k], found faster for large v (the light estimate's median). `v` is
// reordered.
float ValueOfRank(std::vector<float>& v, size_t k);

// Opening then closing with elliptical kernels of the given radii, then
// removal of 8-connected blobs smaller than `min_area` pixels, except those of
// at least `near_min_area` pixels within `near_px` of a blob of `min_area` or
// more (near_px 0: none kept); returns the number removed.
int CleanMask(cv::Mat& mask, int open_radius, int close_radius, int min_area, int near_px = 0,
              int near_min_area = 0);

}  // namespace irbench
