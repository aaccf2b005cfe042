#include "tracker/silhouette/background_model.h"

#include "tracker/silhouette/internal/box.h"
#include "common/error.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <tuple>

namespace irbench {
namespace {
// Fewer pixels than this that follow the light clearly: L cannot be read.
constexpr int kMinLightPixels = 50;
// Fewer sampled screen pixels than this: the screen's level cannot be read.
constexpr size_t kMinScreenSamples = 20;

// The root sum of squares of a Gaussian kernel of `sigma` px (or of its
// Laplacian), as OpenCV applies them: white noise filtered by it keeps this
// share of its standard deviation.
double GaussianNorm(double sigma, bool laplacian) {
  const int half = static_cast<int>(std::ceil(5 * sigma)) + 2;
  cv::Mat delta = cv::Mat::zeros(2 * half + 1, 2 * half + 1, CV_32F), out;
  delta.at<float>(half, half) = 1;
  cv::GaussianBlur(delta, out, cv::Size(), sigma);
  if (laplacian) cv::Laplacian(out, out, CV_32F);
  return std::sqrt(out.dot(out));
}

std::pair<double, double> MeanAndVariance(const std::vector<double>& v) {
  const double n = static_cast<double>(v.size());
  double mean = 0, var = 0;
  for (double x : v) mean += x / n;
  for (double x : v) var += (x - mean) * (x - mean) / n;
  return {mean, var};
}

// Per pixel, the slope of the frames' I on a regressor x: by least squares
// (`cov` = Σ I·(x − x̄) over the n frames, `var` x's variance), or else each
// pixel scaling with x (μ / x̄), when `scale` and x̄ > 1 (else 0). CV_64F.
cv::Mat Slopes(bool by_regression, bool scale, const cv::Mat& cov, int n, double var, const cv::Mat& mean,
               double x_mean) {
  if (by_regression) return cov / (n * var);
  if (scale && x_mean > 1) return mean / x_mean;
  return cv::Mat::zeros(mean.size(), CV_64F);
}

// The line I ≈ a + b·x per pixel over the frames (CV_64F), given its slopes
// b: a through the mean, and the residual's σ over `dof` degrees of freedom,
// floored at `min_sigma`.
struct PixelLines {
  cv::Mat a, b, sigma;
};
PixelLines FitLines(const std::vector<cv::Mat>& frames, const std::vector<double>& x, double x_mean,
                    const cv::Mat& mean, const cv::Mat& b, int dof, double min_sigma) {
  PixelLines lines;
  lines.b = b;
  lines.a = mean - b * x_mean;
  cv::Mat sq = cv::Mat::zeros(mean.size(), CV_64F);
  for (size_t i = 0; i < frames.size(); ++i) {
    const cv::Mat r = frames[i] - (lines.a + b * x[i]);
    sq += r.mul(r);
  }
  cv::sqrt(sq / dof, lines.sigma);
  lines.sigma = cv::max(lines.sigma, min_sigma);
  return lines;
}

// The median over the sampled pixels of (I − a) / b: the level each one's
// line reads in `frame`. a and b come in arrays of their own, in the
// samples' order: one read scattered over the frame instead of three.
float MedianLevel(const cv::Mat& frame, const std::vector<std::pair<int, int>>& samples,
                  const std::vector<float>& a, const std::vector<float>& b) {
  thread_local std::vector<float> levels;
  levels.resize(samples.size());
  for (size_t i = 0; i < samples.size(); ++i) {
    const auto [y, x] = samples[i];
    levels[i] = (frame.ptr<uint8_t>(y)[x] - a[i]) / b[i];
  }
  return ValueOfRank(levels, levels.size() / 2);
}
}  // namespace

// By way of a sample: the sample's quantiles about k bracket the value, one
// pass counts and gathers the values between them, and only those are
// selected from. When the bracket misses (rarely: it spans many standard
// errors of the sample quantile), the whole vector is selected from.
float ValueOfRank(std::vector<float>& v, size_t k) {
  const size_t n = v.size();
  constexpr size_t kStep = 8;
  if (n < 64 * kStep) {
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
    return v[k];
  }
  thread_local std::vector<float> sample, between;
  sample.clear();
  for (size_t i = 0; i < n; i += kStep) sample.push_back(v[i]);
  const size_t m = sample.size();
  const size_t at = k * m / n, margin = 4 * static_cast<size_t>(std::sqrt(double(m))) + 2;
  const size_t lo_rank = at > margin ? at - margin : 0, hi_rank = std::min(m - 1, at + margin);
  std::nth_element(sample.begin(), sample.begin() + static_cast<std::ptrdiff_t>(hi_rank), sample.end());
  const float hi = sample[hi_rank];
  std::nth_element(sample.begin(), sample.begin() + static_cast<std::ptrdiff_t>(lo_rank),
                   sample.begin() + static_cast<std::ptrdiff_t>(hi_rank));
  const float lo = sample[lo_rank];
  // Branch-free: the values fall either side of the bracket at random.
  size_t below = 0, count = 0;
  between.resize(n);
  for (const float x : v) {
    below += x < lo;
    between[count] = x;
    count += (x >= lo) & (x <= hi);
  }
  between.resize(count);
  if (k >= below && k < below + between.size()) {
    const auto target = between.begin() + static_cast<std::ptrdiff_t>(k - below);
    std::nth_element(between.begin(), target, between.end());
    return *target;
  }
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

std::optional<BackgroundKind> ParseBackgroundKind(const std::string& name) {
  if (name == "flicker") return BackgroundKind::kFlicker;
  if (name == "plain") return BackgroundKind::kPlain;
  return std::nullopt;
}

const char* BackgroundKindName(BackgroundKind kind) { return kind == BackgroundKind::kPlain ? "plain" : "flicker"; }

void BackgroundOptions::Check() const {
  if (!(threshold_sigma > 0)) throw InputError("", "background.threshold_sigma", "must be > 0");
  if (!(pool_sigma >= 0 && pool_threshold > 0)) {
    throw InputError("", "background.pool_sigma", "must be >= 0, pool_threshold > 0");
  }
  if (!(pool_weak_threshold > 0 && pool_weak_threshold <= pool_threshold)) {
    throw InputError("", "background.pool_weak_threshold", "must be in (0, pool_threshold]");
  }
  // sigma 0 (a saturated or constant pixel) would make the normalised difference infinite.
  if (!(min_sigma > 0)) throw InputError("", "background.min_sigma", "must be > 0");
  if (!(slope_sigma >= 0 && slope_sigma <= 32)) {
    throw InputError("", "background.slope_sigma", "must be in [0, 32] (0: no smoothing)");
  }
  if (open_radius < 0 || close_radius < 0) throw InputError("", "background.morphology_radii", "must be >= 0");
  if (!(min_blob_fraction >= 0 && min_blob_fraction < 1)) {
    throw InputError("", "background.min_blob_fraction", "must be in [0, 1)");
  }
  if (!(near_blob_px >= 0)) throw InputError("", "background.near_blob_px", "must be non-negative");
  if (!(near_blob_min_fraction >= 0 && near_blob_min_fraction < 1)) {
    throw InputError("", "background.near_blob_min_fraction", "must be in [0, 1)");
  }
  if (!(outline_sigma >= 0 && outline_sigma <= 8)) {
    throw InputError("", "background.outline_sigma", "must be in [0, 8] (0: no outline refinement)");
  }
  if (outline_band < 0 || outline_band > 8) throw InputError("", "background.outline_band", "must be in [0, 8]");
  if (!(outline_min_laplacian >= 0)) throw InputError("", "background.outline_min_laplacian", "must be >= 0");
  if (!(outline_doubt >= 0)) throw InputError("", "background.outline_doubt", "must be >= 0");
  if (!(outline_max_hole >= 0)) throw InputError("", "background.outline_max_hole", "must be >= 0");
}

// The training frames and what every step of Train reads of them.
struct BackgroundModel::TrainingSet {
  // Computes the statistics of `frames` (CV_8UC1, one size, at least one).
  TrainingSet(const std::vector<cv::Mat>& training_frames, const BackgroundOptions& options, const cv::Mat& screen);

  const std::vector<cv::Mat>& frames;
  int n = 0;
  cv::Size size;
  bool flicker = false;  // the flicker model
  // Screen pixels follow the projection, not L: they take no part in L (the
  // mean of the other pixels) and are modelled on the screen's own level.
  bool own_screen = false;
  cv::Mat stage;               // CV_8U, 255 off the screens with own_screen; else empty (every pixel)
  std::vector<double> light;   // L per frame: the mean grey level over `stage`
  double light_mean = 0, light_var = 0;
  std::vector<cv::Mat> f64;    // the frames, CV_64F
  cv::Mat sum_l;               // Σ I·(L − L̄) per pixel, CV_64F
  cv::Mat mean;                // μ per pixel, CV_64F
  // The slopes' smoothing (Gaussian sigma, px), and what it leaves of their noise.
  double slope_px = 0;
  double se_scale = 1;
};

BackgroundModel::TrainingSet::TrainingSet(const std::vector<cv::Mat>& training_frames,
                                          const BackgroundOptions& options, const cv::Mat& screen)
    : frames(training_frames), n(static_cast<int>(training_frames.size())), size(training_frames[0].size()) {
  own_screen = options.model == BackgroundKind::kFlicker && !screen.empty() && cv::countNonZero(screen) >= 50;
  stage = own_screen ? cv::Mat(screen == 0) : cv::Mat();
  light.assign(n, 0.0);
  for (int i = 0; i < n; ++i) light[i] = cv::mean(frames[i], stage)[0];
  std::tie(light_mean, light_var) = MeanAndVariance(light);
  f64.resize(n);
  for (int i = 0; i < n; ++i) frames[i].convertTo(f64[i], CV_64F);
  cv::Mat sum = cv::Mat::zeros(size, CV_64F);
  sum_l = cv::Mat::zeros(size, CV_64F);
  for (int i = 0; i < n; ++i) {
    sum += f64[i];
    sum_l += f64[i] * (light[i] - light_mean);
  }
  mean = sum / n;
  flicker = options.model == BackgroundKind::kFlicker;
  slope_px = options.slope_sigma * size.width / 320.0;
  se_scale = slope_px > 0 ? GaussianNorm(slope_px, false) : 1.0;
}

std::optional<BackgroundModel> BackgroundModel::Train(const std::vector<cv::Mat>& frames,
                                                      const BackgroundOptions& options, const cv::Mat& screen) {
  options.Check();
  if (frames.empty()) return std::nullopt;
  const cv::Size size = frames[0].size();
  if (!screen.empty() && (screen.size() != size || screen.type() != CV_8UC1)) return std::nullopt;
  for (const cv::Mat& f : frames) {
    if (f.size() != size || f.type() != CV_8UC1) return std::nullopt;
  }
  const TrainingSet set(frames, options, screen);

  BackgroundModel m;
  m.options_ = options;
  m.mean_light_ = set.light_mean;
  // With (almost) no light change in training, b is not identifiable: plain.
  bool regress = set.flicker && set.light_var > 0.05 && set.n >= 3;
  // A regression whose slopes too few pixels show significantly (a light
  // change in training too small for the noise) falls back to pixels scaling
  // with the light: the whole stage still brightens with a flash, and L must
  // follow it.
  cv::Mat light_pixels;  // CV_8U: pixels whose b is large enough to read L from
  if (set.own_screen) m.screen_ = screen.clone();
  int dof = m.FitLight(set, regress, light_pixels);
  if (regress && cv::countNonZero(light_pixels) < kMinLightPixels) {
    regress = false;
    dof = m.FitLight(set, false, light_pixels);
  }
  std::vector<double> screen_level(set.n, 0.0);
  if (!m.screen_.empty()) m.FitScreen(set, screen_level);
  m.light_pixel_count_ = cv::countNonZero(light_pixels);
  m.SampleLightPixels(light_pixels);
  m.MeasureTrainingNoise(set, regress, dof, screen_level);
  return m;
}

int BackgroundModel::FitLight(const TrainingSet& set, bool by_regression, cv::Mat& light_pixels) {
  const int n = set.n;
  const cv::Size size = set.size;
  cv::Mat b = Slopes(by_regression, set.flicker, set.sum_l, n, set.light_var, set.mean, set.light_mean);
  if (by_regression && set.slope_px > 0) {
    // Over the stage's pixels only: the screens' slopes are another light's.
    if (set.stage.empty()) {
      cv::GaussianBlur(b, b, cv::Size(), set.slope_px);
    } else {
      cv::Mat weight, weighted;
      set.stage.convertTo(weight, CV_64F, 1.0 / 255);
      cv::GaussianBlur(b.mul(weight), weighted, cv::Size(), set.slope_px);
      cv::GaussianBlur(weight, weight, cv::Size(), set.slope_px);
      b = weighted / cv::max(weight, 1e-6);
    }
  }
  const int dof = std::max(1, n - (by_regression ? 2 : 1));
  const PixelLines lines = FitLines(set.f64, set.light, set.light_mean, set.mean, b, dof, options_.min_sigma);
  lines.a.convertTo(a_, CV_32F);
  lines.b.convertTo(b_, CV_32F);
  lines.sigma.convertTo(sigma_, CV_32F);
  light_pixels = cv::Mat::zeros(size, CV_8U);
  if (set.flicker && !by_regression) light_pixels = b_ > 0.2;
  if (by_regression) {
    for (int y = 0; y < size.height; ++y) {
      const float* bp = b_.ptr<float>(y);
      const float* sp = sigma_.ptr<float>(y);
      uint8_t* lp = light_pixels.ptr<uint8_t>(y);
      for (int x = 0; x < size.width; ++x) {
        // b's standard error is σ / (sqrt(n) · std(L)), times the
        // smoothing kernel's norm.
        lp[x] = bp[x] > 0.2 && bp[x] > 3 * set.se_scale * sp[x] / std::sqrt(n * set.light_var) ? 255 : 0;
      }
    }
  }
  if (!screen_.empty()) light_pixels.setTo(0, screen_);
  return dof;
}

void BackgroundModel::FitScreen(const TrainingSet& set, std::vector<double>& screen_level) {
  const int n = set.n;
  for (int i = 0; i < n; ++i) screen_level[i] = cv::mean(set.frames[i], screen_)[0];
  const auto [g_mean, g_var] = MeanAndVariance(screen_level);
  mean_screen_ = g_mean;
  cv::Mat sum_g = cv::Mat::zeros(set.size, CV_64F);
  for (int i = 0; i < n; ++i) sum_g += set.f64[i] * (screen_level[i] - g_mean);
  const bool screen_regress =
      g_var > 0.05 && n >= 3 && FitScreenLines(set, screen_level, g_mean, g_var, sum_g, true);
  if (!screen_regress) {
    FitScreenLines(set, screen_level, g_mean, g_var, sum_g, false);
    std::fill(screen_level.begin(), screen_level.end(), -1.0);  // read from the frames
  }
}

bool BackgroundModel::FitScreenLines(const TrainingSet& set,
                                     const std::vector<double>& screen_level,
                                     double g_mean,
                                     double g_var,
                                     const cv::Mat& sum_g,
                                     bool by_regression) {
  const int n = set.n;
  const cv::Size size = set.size;
  const cv::Mat b = Slopes(by_regression, true, sum_g, n, g_var, set.mean, g_mean);
  const PixelLines lines = FitLines(set.f64, screen_level, g_mean, set.mean, b,
                                    std::max(1, n - (by_regression ? 2 : 1)), options_.min_sigma);
  cv::Mat a32, b32, s32;
  lines.a.convertTo(a32, CV_32F);
  lines.b.convertTo(b32, CV_32F);
  lines.sigma.convertTo(s32, CV_32F);
  a32.copyTo(a_, screen_);
  b32.copyTo(b_, screen_);
  s32.copyTo(sigma_, screen_);
  // G is read from the pixels that follow it clearly (every other row
  // and column): b well above its standard error, or without the
  // regression, a pixel bright enough to scale.
  screen_samples_.clear();
  screen_a_.clear();
  screen_b_.clear();
  for (int y = 0; y < size.height; y += 2) {
    const uint8_t* sp = screen_.ptr<uint8_t>(y);
    const float* bp = b_.ptr<float>(y);
    const float* gp = sigma_.ptr<float>(y);
    const double* mp = set.mean.ptr<double>(y);
    for (int x = 0; x < size.width; x += 2) {
      if (!sp[x] || !(bp[x] > 0.2)) continue;
      if (by_regression ? bp[x] <= 3 * gp[x] / std::sqrt(n * g_var) : mp[x] <= 4) continue;
      screen_samples_.push_back({y, x});
      screen_a_.push_back(a_.ptr<float>(y)[x]);
      screen_b_.push_back(bp[x]);
    }
  }
  return screen_samples_.size() >= kMinScreenSamples;
}

void BackgroundModel::SampleLightPixels(const cv::Mat& light_pixels) {
  // The light is read from every other row and column: a quarter of the
  // pixels is plenty for a median.
  for (int y = 0; y < light_pixels.rows; y += 2) {
    const uint8_t* lp = light_pixels.ptr<uint8_t>(y);
    for (int x = 0; x < light_pixels.cols; x += 2) {
      if (lp[x]) {
        light_samples_.push_back({y, x});
        light_a_.push_back(a_.ptr<float>(y)[x]);
        light_b_.push_back(b_.ptr<float>(y)[x]);
      }
    }
  }
}

void BackgroundModel::MeasureTrainingNoise(const TrainingSet& set,
                                           bool regress,
                                           int dof,
                                           const std::vector<double>& screen_level) {
  const int n = set.n;
  const cv::Size size = set.size;
  const std::vector<double>& light = set.light;
  const bool pool = set.flicker && options_.pool_sigma > 0, outline = set.flicker && options_.outline_sigma > 0;
  if (!(pool || outline)) return;
  double pooled_sq = 0, smooth_sq = 0, laplacian_sq = 0;
  size_t count = 0;
  // With the light regressed, on the half of the frames whose light is
  // nearest the mean: the ends of a calibration sweep hold the smoothed
  // slopes' error times a light change several times a sequence's (its
  // content stays within ±10% of the sweep's middle, flashes aside), and
  // set in it the thresholds rose (closed loop 0.877 against 0.886).
  std::vector<double> off(n);
  for (int i = 0; i < n; ++i) off[i] = std::abs(light[i] - set.light_mean);
  std::vector<double> sorted_off = off;
  std::sort(sorted_off.begin(), sorted_off.end());
  const double near = regress ? sorted_off[(n - 1) / 2] : std::numeric_limits<double>::infinity();
  for (int i = 0; i < n; ++i) {
    if (off[i] > near) continue;
    const cv::Mat& frame = set.frames[i];
    const double gain = screen_level[i] >= 0 && mean_screen_ > 0 ? screen_level[i] / mean_screen_
                                                                   : EstimateScreenGain(frame);
    const cv::Mat z = Normalised(frame, static_cast<float>(regress ? light[i] : EstimateLight(frame)),
                                 static_cast<float>(gain));
    if (pool) {
      cv::Mat pooled;
      cv::GaussianBlur(z, pooled, cv::Size(), PoolSigmaPx(size.width));
      pooled_sq += pooled.dot(pooled);
    }
    if (outline) {
      cv::Mat smooth, laplacian;
      cv::GaussianBlur(z.mul(sigma_), smooth, cv::Size(), OutlineSigmaPx(size.width));
      cv::Laplacian(smooth, laplacian, CV_32F);
      smooth_sq += smooth.dot(smooth);
      laplacian_sq += laplacian.dot(laplacian);
    }
    count += z.total();
  }
  // Floors: what 8-bit rounding alone gives after the same filters (white
  // noise of 1/√12 grey levels a pixel; in z, over the floor of σ). Frames
  // without noise (the `clean` preset) would otherwise set the thresholds
  // at nothing (the old floor of 1e-3: a thousandth of z or of a grey
  // level), and the faintest tail of the blurred outline would join the body.
  const auto filtered_norm = GaussianNorm;
  const double rounding = 1 / std::sqrt(12.0);
  // The sample σ of few frames makes z's spread shrink by sqrt(dof / n).
  const auto rms = [&](double sum_sq, double floor) {
    return std::max(floor, std::sqrt(sum_sq / count * n / dof));
  };
  if (pool) {
    const double floor = filtered_norm(PoolSigmaPx(size.width), false) * rounding / options_.min_sigma;
    pooled_noise_ = rms(pooled_sq, floor);
  }
  if (outline) {
    const double sigma = OutlineSigmaPx(size.width);
    smoothed_noise_ = rms(smooth_sq, filtered_norm(sigma, false) * rounding);
    outline_noise_ = rms(laplacian_sq, filtered_norm(sigma, true) * rounding);
  }
}

cv::Mat BackgroundModel::Normalised(const cv::Mat& frame, float light, float screen_gain) const {
  cv::Mat z(frame.size(), CV_32F);
  const float screen_sigma_scale = std::max(1.0f, screen_gain);
  const float screen_level = screen_gain * static_cast<float>(mean_screen_);
  for (int y = 0; y < frame.rows; ++y) {
    const uint8_t* ip = frame.ptr<uint8_t>(y);
    const float* ap = a_.ptr<float>(y);
    const float* bp = b_.ptr<float>(y);
    const float* sp = sigma_.ptr<float>(y);
    const uint8_t* scr = screen_.empty() ? nullptr : screen_.ptr<uint8_t>(y);
    float* zp = z.ptr<float>(y);
    for (int x = 0; x < frame.cols; ++x) {
      zp[x] = scr && scr[x] ? (ip[x] - (ap[x] + bp[x] * screen_level)) / (screen_sigma_scale * sp[x])
                            : (ip[x] - (ap[x] + bp[x] * light)) / sp[x];
    }
  }
  return z;
}

double BackgroundModel::EstimateScreenGain(const cv::Mat& frame) const {
  if (screen_.empty() || screen_samples_.size() < kMinScreenSamples || !(mean_screen_ > 0)) return 1.0;
  return MedianLevel(frame, screen_samples_, screen_a_, screen_b_) / mean_screen_;
}

cv::Mat BackgroundModel::Expected(double light) const {
  cv::Mat e = a_ + b_ * light;
  return e;
}

double BackgroundModel::EstimateLight(const cv::Mat& frame) const {
  if (light_pixel_count_ < kMinLightPixels || light_samples_.empty()) return mean_light_;
  return MedianLevel(frame, light_samples_, light_a_, light_b_);
}

SilhouetteResult BackgroundModel::Segment(const cv::Mat& frame) const {
  CV_Assert(frame.type() == CV_8UC1 && frame.size() == a_.size());
  SilhouetteResult r;
  r.light_level = options_.model == BackgroundKind::kFlicker ? EstimateLight(frame) : mean_light_;
  r.screen_gain = EstimateScreenGain(frame);
  const cv::Mat z = Normalised(frame, static_cast<float>(r.light_level), static_cast<float>(r.screen_gain));
  r.raw = cv::abs(z) > options_.threshold_sigma;
  if (options_.model == BackgroundKind::kFlicker && options_.pool_sigma > 0) {
    cv::Mat pooled;
    cv::GaussianBlur(z, pooled, cv::Size(), PoolSigmaPx(frame.cols));
    // Hysteresis: weak pooled evidence counts where it connects to strong.
    // strong = |pooled| > pool threshold or raw; weak = |pooled| > the weak
    // threshold or strong (thresholds in float, as cv::compare takes them).
    const float strong_above = static_cast<float>(options_.pool_threshold * pooled_noise_);
    const float weak_above = static_cast<float>(options_.pool_weak_threshold * pooled_noise_);
    // The weak pixels 8-connected to a strong one, by a flood from the strong
    // ones (the same as labelling the weak mask's components and keeping
    // those holding a strong pixel, at a fraction of the cost: the region is
    // small against the image). `weak` has a one-pixel border of zeros, so
    // no neighbour needs a bounds check.
    const int w = pooled.cols, h = pooled.rows, stride = w + 2;
    cv::Mat weak = cv::Mat::zeros(h + 2, stride, CV_8U);
    cv::Mat grown = cv::Mat::zeros(h, w, CV_8U);
    thread_local std::vector<int> stack;
    stack.clear();
    for (int y = 0; y < h; ++y) {
      const float* pp = pooled.ptr<float>(y);
      const uint8_t* rp = r.raw.ptr<uint8_t>(y);
      uint8_t* wp = weak.ptr<uint8_t>(y + 1) + 1;
      uint8_t* gp = grown.ptr<uint8_t>(y);
      for (int x = 0; x < w; ++x) {
        const float a = std::abs(pp[x]);
        if (a > strong_above || rp[x]) {
          gp[x] = 255;
          stack.push_back((y + 1) * stride + x + 1);
        } else if (a > weak_above) {
          wp[x] = 255;  // weak and not yet reached
        }
      }
    }
    uint8_t* weak_at = weak.data;
    const int offsets[8] = {-stride - 1, -stride, -stride + 1, -1, 1, stride - 1, stride, stride + 1};
    while (!stack.empty()) {
      const int i = stack.back();
      stack.pop_back();
      for (const int o : offsets) {
        const int j = i + o;
        if (weak_at[j]) {
          weak_at[j] = 0;
          grown.at<uint8_t>(j / stride - 1, j % stride - 1) = 255;
          stack.push_back(j);
        }
      }
    }
    // Pooling spreads a region by about the window's radius: take it back.
    const int r_px = std::max(1, static_cast<int>(std::lround(PoolSigmaPx(frame.cols))));
    cv::erode(grown, grown, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * r_px + 1, 2 * r_px + 1)));
    r.raw |= grown;
  }
  r.mask = r.raw.clone();
  const double scale = frame.cols / 320.0;
  const bool refine = options_.model == BackgroundKind::kFlicker && options_.outline_sigma > 0;
  const int min_area = static_cast<int>(options_.min_blob_fraction * frame.total());
  const int near_px = static_cast<int>(std::lround(options_.near_blob_px * scale));
  const int near_min_area = static_cast<int>(options_.near_blob_min_fraction * frame.total());
  r.blobs_removed = CleanMask(r.mask, refine ? 0 : static_cast<int>(std::lround(options_.open_radius * scale)),
                              static_cast<int>(std::lround(options_.close_radius * scale)), min_area, near_px,
                              near_min_area);
  if (refine) {
    RefineOutline(z, r.mask);
    // Parts the refinement cut off, small: dropped as the blobs above.
    r.blobs_removed += CleanMask(r.mask, 0, 0, min_area, near_px, near_min_area);
  }
  // Darker than the stage, smoothed: within the mask's rows only, where
  // shadow removal reads it. A blur of a view of z reads z's pixels around
  // it, so the values are those of the whole image's blur; the view starts
  // at a multiple of 64 columns and runs to the right edge, so each pixel
  // takes the same vectorised path (and rounding) as in the whole image.
  r.darker = cv::Mat::zeros(frame.size(), CV_8U);
  cv::Rect box = cv::boundingRect(r.mask);
  if (!box.empty()) {
    box.x &= ~63;
    box.width = frame.cols - box.x;
    cv::Mat smooth;
    cv::GaussianBlur(z(box), smooth, cv::Size(), 1.5 * frame.cols / 320.0);
    r.darker(box).setTo(255, smooth < 0);
  }
  return r;
}

void BackgroundModel::RefineOutline(const cv::Mat& z, cv::Mat& mask) const {
  const cv::Rect box = cv::boundingRect(mask);
  if (box.empty()) return;
  const double scale = z.cols / 320.0;
  const double sigma = OutlineSigmaPx(z.cols);
  // The side of the outline is told by the sign of a wider smoothing of the
  // difference (the body brighter or darker than the stage there).
  const double side_sigma = 2 * sigma;
  const int band = static_cast<int>(std::lround(options_.outline_band * scale));
  // Room for the band, the wider Gaussian (OpenCV's float kernels reach 4
  // sigma) and the Laplacian, so that every value read is the whole image's.
  const int margin = band + static_cast<int>(std::ceil(4 * side_sigma)) + 2;
  const cv::Rect roi = silhouette_internal::GrownWithin(box, margin, z.size());
  // The blur acts on intensities: back from z to grey levels, I − μ(t).
  const cv::Mat difference = z(roi).mul(sigma_(roi));
  cv::Mat smooth, laplacian, side;
  cv::GaussianBlur(difference, smooth, cv::Size(), sigma);
  cv::Laplacian(smooth, laplacian, CV_32F);
  cv::GaussianBlur(difference, side, cv::Size(), side_sigma);
  cv::Mat local = mask(roi);  // a view: written back at the end
  // The band about the outline (band 0: a 1x1 kernel, the mask itself).
  cv::Mat outer, inner;
  const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * band + 1, 2 * band + 1));
  cv::dilate(local, outer, kernel);
  cv::erode(local, inner, kernel);
  const float min_laplacian = static_cast<float>(options_.outline_min_laplacian * outline_noise_);
  const float doubt = static_cast<float>(options_.outline_doubt * smoothed_noise_);
  cv::Mat refined = local.clone();
  for (int y = 0; y < roi.height; ++y) {
    const uint8_t* op = outer.ptr<uint8_t>(y);
    const uint8_t* ip = inner.ptr<uint8_t>(y);
    const float* sp = smooth.ptr<float>(y);
    const float* lp = laplacian.ptr<float>(y);
    const float* dp = side.ptr<float>(y);
    uint8_t* rp = refined.ptr<uint8_t>(y);
    for (int x = 0; x < roi.width; ++x) {
      if (!op[x]) continue;                             // beyond the band, outside
      if (ip[x] && std::abs(sp[x]) >= doubt) continue;  // inside, clearly foreground
      if (std::abs(lp[x]) < min_laplacian) continue;    // no curvature to tell by: left as it is
      // Inside a blurred step the profile bends away from the stage's level.
      rp[x] = (dp[x] >= 0 ? lp[x] < 0 : lp[x] > 0) ? 255 : 0;
    }
  }
  // Holes the refinement opened inside the mask (wholly within it before),
  // small: the Laplacian's noise where the body's own brightness varies.
  // Larger ones are gaps the closing had filled.
  const int max_hole = static_cast<int>(std::lround(options_.outline_max_hole * scale * scale));
  if (max_hole > 0) {
    cv::Mat labels;
    const cv::Mat background = refined == 0;
    const int count = cv::connectedComponents(background, labels, 4, CV_32S);
    std::vector<int> area(count, 0);
    std::vector<uint8_t> outside(count, 0);  // holds a pixel outside the mask before
    for (int y = 0; y < labels.rows; ++y) {
      const int* lp = labels.ptr<int>(y);
      const uint8_t* mp = local.ptr<uint8_t>(y);
      for (int x = 0; x < labels.cols; ++x) {
        ++area[lp[x]];
        if (!mp[x]) outside[lp[x]] = 1;
      }
    }
    for (int y = 0; y < labels.rows; ++y) {
      const int* lp = labels.ptr<int>(y);
      uint8_t* rp = refined.ptr<uint8_t>(y);
      for (int x = 0; x < labels.cols; ++x) {
        if (lp[x] > 0 && !outside[lp[x]] && area[lp[x]] <= max_hole) rp[x] = 255;
      }
    }
  }
  refined.copyTo(local);
}

namespace {

// CleanMask on `mask`, a view that holds every nonzero pixel of its image
// with room about them for the morphology.
int CleanRegion(cv::Mat& mask, int open_radius, int close_radius, int min_area, int near_px, int near_min_area) {
  auto kernel = [](int r) {
    return cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * r + 1, 2 * r + 1));
  };
  if (open_radius > 0) cv::morphologyEx(mask, mask, cv::MORPH_OPEN, kernel(open_radius));
  if (close_radius > 0) cv::morphologyEx(mask, mask, cv::MORPH_CLOSE, kernel(close_radius));
  if (min_area <= 1) return 0;
  // connectedComponents and one pass for the areas: connectedComponentsWithStats
  // takes several times longer in OpenCV 4.6.
  cv::Mat labels;
  const int count = cv::connectedComponents(mask, labels, 8, CV_32S);
  std::vector<int> area(count, 0);
  for (int y = 0; y < labels.rows; ++y) {
    const int* lp = labels.ptr<int>(y);
    for (int x = 0; x < labels.cols; ++x) ++area[lp[x]];
  }
  std::vector<uint8_t> keep(count, 0);
  int removed = 0;
  // Small blobs of near_min_area or more: kept when near a blob kept by area.
  std::vector<uint8_t> candidate(count, 0);
  for (int i = 1; i < count; ++i) {
    keep[i] = area[i] >= min_area;
    candidate[i] = near_px > 0 && !keep[i] && area[i] >= near_min_area;
  }
  if (std::find(candidate.begin(), candidate.end(), 1) != candidate.end()) {
    // Those touching the kept blobs grown by near_px stay (judged against the
    // blobs kept by area only, so a kept one does not reach further). The
    // kernel is symmetric: a kept pixel lies within it about a candidate's
    // pixel exactly when the candidate grown by it touches a kept pixel, and
    // growing each (small) candidate in its own box is far cheaper than
    // growing the kept blobs over the whole image.
    std::vector<cv::Rect> box(count);
    for (int y = 0; y < labels.rows; ++y) {
      const int* lp = labels.ptr<int>(y);
      for (int x = 0; x < labels.cols; ++x) {
        if (candidate[lp[x]]) box[lp[x]] |= cv::Rect(x, y, 1, 1);
      }
    }
    const std::vector<uint8_t> kept_by_area = keep;
    const cv::Mat grow = kernel(near_px);
    for (int i = 1; i < count; ++i) {
      if (!candidate[i]) continue;
      const cv::Rect roi = cv::Rect(box[i].x - near_px, box[i].y - near_px, box[i].width + 2 * near_px,
                                    box[i].height + 2 * near_px) &
                           cv::Rect(0, 0, mask.cols, mask.rows);
      const cv::Mat local_labels = labels(roi);
      cv::Mat blob = local_labels == i;
      cv::dilate(blob, blob, grow);
      for (int y = 0; y < roi.height && !keep[i]; ++y) {
        const int* lp = local_labels.ptr<int>(y);
        const uint8_t* bp = blob.ptr<uint8_t>(y);
        for (int x = 0; x < roi.width; ++x) {
          if (bp[x] && kept_by_area[lp[x]]) {
            keep[i] = 1;
            break;
          }
        }
      }
    }
  }
  for (int i = 1; i < count; ++i) removed += !keep[i];
  if (removed == 0) return 0;
  for (int y = 0; y < mask.rows; ++y) {
    const int* lp = labels.ptr<int>(y);
    uint8_t* mp = mask.ptr<uint8_t>(y);
    for (int x = 0; x < mask.cols; ++x) mp[x] = keep[lp[x]] ? 255 : 0;
  }
  return removed;
}

}  // namespace

int CleanMask(cv::Mat& mask, int open_radius, int close_radius, int min_area, int near_px, int near_min_area) {
  // Only the box about the nonzero pixels, grown by what the opening and the
  // closing can reach (their dilations, and the erosions that read around
  // them), changes or is read: the same result for a fraction of the image.
  const cv::Rect box = cv::boundingRect(mask);
  if (box.empty()) return 0;
  const int margin = 2 * (std::max(open_radius, 0) + std::max(close_radius, 0)) + 1;
  const cv::Rect roi = silhouette_internal::GrownWithin(box, margin, mask.size());
  cv::Mat local = mask(roi);
  return CleanRegion(local, open_radius, close_radius, min_area, near_px, near_min_area);
}

}  // namespace irbench
