#pragma once
// The `[camera]` section of an installation's configuration file: what a measurement asks of its
// camera (CameraSettings) and the twin camera's sensor model (psi::CameraParams), with one list
// of valid ranges that the TOML reader, the factory and the cameras' configure() share
// (docs/camera.md lists each key, its unit, default and source).
//
//   [camera]
//   width_px = 256            # a region of interest of the 1440 x 1080 sensor
//   pixel_format = "Mono12"   # Mono8, Mono12, Mono16
//   exposure_s = 1e-3
//   full_well_e = 10500.0     # the twin's sensor only
//
// The section is read here, in the camera module, and not by config::load_project_config:
// `config` sits below `psi` (whose CameraParams is the sensor model) and below `camera`, so it
// cannot hold the section's struct; runtime::load_installation_config reads [safety] the same
// way from above. instrument_config.hpp reads the whole file (design, twin, safety, camera) and
// then rejects unknown keys.
#include <string>
#include <string_view>

#include "piezoshift/camera/settings.hpp"
#include "piezoshift/core/bounds.hpp"
#include "piezoshift/io/config_file.hpp"
#include "piezoshift/psi/fizeau_simulation.hpp"

namespace piezoshift::camera {

//! Largest side of a frame [px]: the PNG reader's and the Fizeau simulation's limit.
inline constexpr int kMaxFrameSide_px = 2048;
//! Largest stream buffer pool: 64 frames (psi's frame-set bound), 512 MiB of 2048 x 2048 Mono16.
inline constexpr int kMaxBufferCount = 64;

//! The `[camera]` section. Defaults: a FLIR Blackfly S BFS-PGE-16S2M (Sony IMX273, GigE Vision)
//! read through a 256 x 256 region of interest (docs/camera.md gives the sources).
struct CameraConfig {
  CameraSettings settings{
      .width_px = 256,
      .height_px = 256,
      .format = PixelFormat::kMono12,  //!< the IMX273's 12-bit ADC
      .exposure_s = 1e-3,              //!< short enough to freeze the plate between steps
      .gain_dB = 0.0,                  //!< unity: full well maps to full scale
      .trigger = TriggerSource::kSoftware,
      .readout_s = 1.0 / 78.0,  //!< 78 frames/s at full resolution over GigE
      .buffer_count = 16,
  };
  //! The twin's sensor. exposure_s and bit_depth are not keys of their own: they follow
  //! settings.exposure_s and settings.format (sensor_params()).
  psi::CameraParams sensor{
      .exposure_s = 1e-3,
      .full_well_e = 10500.0,  //!< IMX273 saturation capacity (EMVA 1288), ~10.5 ke-
      .mean_fill = 0.45,       //!< the interferometer's light level, not the camera's (psi)
      .visibility = 0.9,       //!< fringe contrast of the cavity, not the camera's (psi)
      .read_noise_e = 2.3,     //!< IMX273 temporal dark noise (EMVA 1288), ~2.3 e- rms
      .shot_noise = true,
      .bit_depth = 12,
  };
  //! The twin only: the fringes washed out (the air in the cavity stirred, a vibration through
  //! the exposure) for frames triggered from this loop time for fringe_loss_s, rendered with
  //! visibility 0; a negative start: never. A test of the fringe lock losing its fringes.
  double fringe_loss_start_s = -1.0;
  double fringe_loss_s = 0.0;
  //! The pupil's radius on the reference plate, which the camera images (the Fizeau's aperture):
  //! the twin renders it, and the fringe lock turns fringes across it into the plate's tilt.
  //! 25 mm, a 50 mm aperture, assumed (psi::FizeauParams; the paper gives none).
  double pupil_radius_m = 0.025;
};

//! Calls visit(section, key, value, bounds) for each numeric value of [camera] (const or not);
//! value is a double or an int. Within these ranges psi::camera_problem() and
//! psi::fizeau_problem()'s size check always pass.
template <typename Config, typename Visit>
void visit_camera_values(Config& c, Visit&& visit) {
  using B = core::Bounds;
  visit("camera", "width_px", c.settings.width_px, B::closed(8, kMaxFrameSide_px));
  visit("camera", "height_px", c.settings.height_px, B::closed(8, kMaxFrameSide_px));
  // Up to 1 s (psi's limit); a phase-shifting exposure is milliseconds.
  visit("camera", "exposure_s", c.settings.exposure_s, B::above(0.0, 1.0));
  // The Blackfly S family's 0 to 48 dB.
  visit("camera", "gain_dB", c.settings.gain_dB, B::closed(0.0, 48.0));
  visit("camera", "readout_s", c.settings.readout_s, B::closed(0.0, 1.0));
  visit("camera", "buffer_count", c.settings.buffer_count, B::closed(1, kMaxBufferCount));
  visit("camera", "full_well_e", c.sensor.full_well_e, B::closed(100.0, 1e7));
  visit("camera", "read_noise_e", c.sensor.read_noise_e, B::closed(0.0, 1000.0));
  visit("camera", "mean_fill", c.sensor.mean_fill, B::open(0.0, 1.0));
  visit("camera", "visibility", c.sensor.visibility, B::above(0.0, 1.0));
  visit("camera", "fringe_loss_start_s", c.fringe_loss_start_s, B::closed(-1.0, 1e6));
  visit("camera", "fringe_loss_s", c.fringe_loss_s, B::closed(0.0, 3600.0));
  // psi::fizeau_problem's range; a Fizeau's aperture is 25 to 300 mm across
  visit("camera", "pupil_radius_m", c.pupil_radius_m, B::open(0.0, 1.0));
}

//! The first value outside its range ("camera.exposure_s = 2 must be in (0, 1]"); "" when valid.
std::string camera_config_problem(const CameraConfig& config);
//! The same check for the settings alone (what configure() is handed).
std::string camera_settings_problem(const CameraSettings& settings);

//! The twin's psi::CameraParams: config.sensor with exposure_s and bit_depth from the settings.
psi::CameraParams sensor_params(const CameraConfig& config);

//! The frame period a camera can keep up: one exposure, then its readout [1/s].
double max_frame_rate_Hz(const CameraSettings& settings) noexcept;

//! "Mono8" -> kMono8 ...; false for any other name.
bool parse_pixel_format(std::string_view name, PixelFormat& format) noexcept;

//! Reads [camera] into config (absent keys keep their values) with the ranges above; the pixel
//! format and trigger by name ("Mono12"; "software", "line"); shot_noise as a bool. InputError
//! naming the file and the key otherwise. Does not call reject_unknown().
void read_camera_section(const io::ConfigFile& file, CameraConfig& config);

}  // namespace piezoshift::camera
