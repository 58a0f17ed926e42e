// Bindings of the plant module (docs/twin.md): the twin's parameters, the twin itself and what it
// reports. Truth and readings are returned as copies: they change at every step.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>

#include "bindings.hpp"
#include "piezoshift/config/project_config.hpp"
#include "piezoshift/plant/twin.hpp"
#include "piezoshift/plant/twin_params.hpp"
#include "values.hpp"

namespace piezoshift::python {

namespace {

namespace pl = ps::plant;

// The DAQ, the amplifier, the stacks and the mechanism: from the AO voltage to the plate's pose.
void bind_actuation_params(py::module_& m) {
  py::class_<pl::DaqParams>(m, "DaqParams")
      .def(py::init<>())
      .PS_RW(pl::DaqParams, sample_time_s)
      .PS_RW(pl::DaqParams, range_V)
      .PS_RW(pl::DaqParams, resolution_bits)
      .PS_RW(pl::DaqParams, ai_noise_V_rms);
  py::class_<pl::AmplifierParams>(m, "AmplifierParams")
      .def(py::init<>())
      .PS_RW(pl::AmplifierParams, gain)
      .PS_RW(pl::AmplifierParams, output_min_V)
      .PS_RW(pl::AmplifierParams, output_max_V)
      .PS_RW(pl::AmplifierParams, average_power_W)
      .PS_RW(pl::AmplifierParams, small_signal_bandwidth_Hz);
  py::class_<pl::HysteresisParams>(m, "HysteresisParams")
      .def(py::init<>())
      .PS_RW(pl::HysteresisParams, hysteresis_fraction)
      .PS_RW(pl::HysteresisParams, play_operators);
  py::class_<pl::CreepParams>(m, "CreepParams")
      .def(py::init<>())
      .PS_RW(pl::CreepParams, per_decade_fraction)
      .PS_RW(pl::CreepParams, shortest_time_constant_s)
      .PS_RW(pl::CreepParams, longest_time_constant_s)
      .PS_RW(pl::CreepParams, terms_per_decade);
  py::class_<pl::PiezoParams>(m, "PiezoParams")
      .def(py::init<>())
      .PS_RW(pl::PiezoParams, hysteresis)
      .PS_RW(pl::PiezoParams, creep)
      .PS_RW(pl::PiezoParams, creep_reference_time_s)
      .PS_V3(pl::PiezoParams, free_stroke_scale);
  py::class_<pl::ContactParams>(m, "ContactParams")
      .def(py::init<>())
      .PS_RW(pl::ContactParams, open_loop_travel_um)
      .PS_RW(pl::ContactParams, open_loop_time_s)
      .PS_RW(pl::ContactParams, stiffness_N_per_um)
      .PS_RW(pl::ContactParams, ball_radius_m)
      .PS_RW(pl::ContactParams, preload_N);
  py::class_<pl::MechanicsParams>(m, "MechanicsParams")
      .def(py::init<>())
      .PS_RW(pl::MechanicsParams, mechanism_damping_ratio)
      .PS_RW(pl::MechanicsParams, modal_damping_ratio);
  py::class_<pl::PlateParams>(m, "PlateParams")
      .def(py::init<>())
      .PS_RW(pl::PlateParams, radius_m)
      .PS_RW(pl::PlateParams, thickness_m)
      .PS_RW(pl::PlateParams, payload_mass_kg);
  py::class_<pl::GeometryParams>(m, "GeometryParams")
      .def(py::init<>())
      .PS_RW(pl::GeometryParams, actuator_radius_m)
      .PS_RW(pl::GeometryParams, first_actuator_angle_deg)
      .PS_V3(pl::GeometryParams, transmission_matrix)
      .PS_V3(pl::GeometryParams, height_errors_um);
}

// The strain gauges, the interferometer and the lab around them.
void bind_sensing_params(py::module_& m) {
  py::enum_<pl::SgsNonlinearityShape>(m, "SgsNonlinearityShape")
      .value("BOW", pl::SgsNonlinearityShape::kBow)
      .value("S_CURVE", pl::SgsNonlinearityShape::kSCurve)
      .value("WAVE", pl::SgsNonlinearityShape::kWave);
  py::class_<pl::SgsParams>(m, "SgsParams")
      .def(py::init<>())
      .PS_RW(pl::SgsParams, full_scale_V)
      .PS_RW(pl::SgsParams, nonlinearity_fraction)
      .PS_RW(pl::SgsParams, nonlinearity_shape)
      .PS_RW(pl::SgsParams, noise_nm_rms)
      .PS_RW(pl::SgsParams, bandwidth_Hz)
      .PS_V3(pl::SgsParams, offset_V)
      .PS_RW(pl::SgsParams, zero_drift_nm_per_K)
      .PS_RW(pl::SgsParams, gauge_creep_fraction)
      .PS_RW(pl::SgsParams, gauge_creep_time_s)
      .PS_RW(pl::SgsParams, flicker_corner_Hz)
      .PS_RW(pl::SgsParams, excitation_drift_ppm_rms)
      .PS_RW(pl::SgsParams, excitation_drift_window_s);
  py::class_<pl::InterferometerParams>(m, "InterferometerParams")
      .def(py::init<>())
      .PS_RW(pl::InterferometerParams, wavelength_nm)
      .PS_RW(pl::InterferometerParams, resolution_nm)
      .PS_RW(pl::InterferometerParams, accuracy_ppm)
      .PS_RW(pl::InterferometerParams, noise_nm_rms)
      .PS_RW(pl::InterferometerParams, cyclic_error_nm)
      .PS_RW(pl::InterferometerParams, dynamic_sample_rate_Hz)
      .PS_RW(pl::InterferometerParams, static_average_s);
  py::class_<pl::LabParams>(m, "LabParams")
      .def(py::init<>())
      .PS_RW(pl::LabParams, temperature_C)
      .PS_RW(pl::LabParams, temperature_rms_K)
      .PS_RW(pl::LabParams, temperature_correlation_time_s)
      .PS_RW(pl::LabParams, structure_time_constant_s)
      .PS_RW(pl::LabParams, metrology_loop_length_m)
      .PS_RW(pl::LabParams, metrology_loop_cte_per_K)
      .PS_RW(pl::LabParams, dead_path_m)
      .PS_RW(pl::LabParams, air_index_per_K);
  py::class_<pl::CavityParams>(m, "CavityParams")
      .def(py::init<>())
      .PS_RW(pl::CavityParams, gap_m)
      .PS_RW(pl::CavityParams, wavelength_nm)
      .PS_RW(pl::CavityParams, pressure_Pa)
      .PS_RW(pl::CavityParams, pressure_rate_rms_Pa_per_s)
      .PS_RW(pl::CavityParams, pressure_rate_correlation_time_s)
      .PS_RW(pl::CavityParams, water_vapour_pressure_Pa)
      .PS_RW(pl::CavityParams, mount_path_length_m)
      .PS_RW(pl::CavityParams, mount_cte_per_K)
      .PS_RW(pl::CavityParams, in_fringes);
}

void bind_twin_values(py::module_& m) {
  py::enum_<pl::AoStatus>(m, "AoStatus")
      .value("OK", pl::AoStatus::kOk)
      .value("CLAMPED", pl::AoStatus::kClamped)
      .value("INVALID", pl::AoStatus::kInvalid);

  using Tr = pl::TwinTruth;
  py::class_<Tr>(m, "TwinTruth")
      .PS_RO(Tr, time_s)
      .PS_V3(Tr, ao_V)
      .PS_V3(Tr, amplifier_V)
      .PS_V3(Tr, free_elongation_um)
      .PS_V3(Tr, stack_elongation_um)
      .PS_V3(Tr, leg_um)
      .PS_RO(Tr, plate_z_um)
      .PS_RO(Tr, theta_x_urad)
      .PS_RO(Tr, theta_y_urad)
      .PS_V3(Tr, points_um)
      .PS_V3(Tr, sgs_V)
      .PS_RO(Tr, air_temperature_C)
      .PS_RO(Tr, structure_temperature_C)
      .PS_RO(Tr, sgs_excitation_drift_ppm)
      .PS_V3(Tr, sgs_zero_flicker_nm)
      .PS_V3(Tr, gauge_creep_um)
      .PS_RO(Tr, interferometer_drift_nm)
      .PS_RO(Tr, air_pressure_Pa)
      .PS_RO(Tr, cavity_drift_nm)
      .PS_RO(Tr, cavity_path_nm);

  using Ifm = pl::InterferometerReading;
  py::class_<Ifm>(m, "InterferometerReading")
      .PS_V3(Ifm, dynamic_um)
      .PS_RO(Ifm, dynamic_time_s)
      .PS_V3(Ifm, static_um)
      .PS_RO(Ifm, static_time_s)
      .PS_RO(Ifm, static_count);

  using Cf = pl::ChannelFault;
  py::class_<Cf>(m, "ChannelFault")
      .def(py::init<>())
      .PS_RW(Cf, amplifier_failed)
      .PS_RW(Cf, sgs_open)
      .PS_RW(Cf, sgs_stuck)
      .PS_RW(Cf, adc_nan)
      .PS_RW(Cf, adc_spike_V)
      .PS_RW(Cf, stack_stiffness_scale);
}

// Twin(design, params, seed) or Twin(config, seed); run() holds ao_V for a number of ticks.
void bind_twin_class(py::module_& m) {
  namespace d = ps::design;
  py::class_<pl::Twin>(m, "Twin")
      .def(py::init<const d::DesignInputs&, const pl::TwinParams&, std::uint64_t>(),
           py::arg("design"), py::arg("params"), py::arg("seed"))
      .def(py::init([](const ps::config::ProjectConfig& c, std::uint64_t seed) {
             return pl::Twin(c.design, c.twin, seed);
           }),
           py::arg("config"), py::arg("seed"))
      .def("write_ao", &pl::Twin::write_ao, py::arg("ao_V"))
      .def("advance", &pl::Twin::advance)
      .def("read_ai", [](const pl::Twin& t) { return to_numpy(t.read_ai()); })
      .def(
          "run",
          [](pl::Twin& t, const Vec3& ao_V, std::size_t ticks) {
            // Holds ao_V for `ticks` periods; returns the AI samples and the true points.
            Array ai({static_cast<py::ssize_t>(ticks), py::ssize_t{3}});
            Array pts({static_cast<py::ssize_t>(ticks), py::ssize_t{3}});
            auto a = ai.mutable_unchecked<2>();
            auto p = pts.mutable_unchecked<2>();
            t.write_ao(ao_V);
            for (std::size_t k = 0; k < ticks; ++k) {
              t.advance();
              const auto kk = static_cast<py::ssize_t>(k);
              for (py::ssize_t j = 0; j < 3; ++j) {
                a(kk, j) = t.read_ai()[j];
                p(kk, j) = t.truth().points_um[j];
              }
            }
            return py::make_tuple(ai, pts);
          },
          py::arg("ao_V"), py::arg("ticks"),
          "Holds ao_V for `ticks` control periods; returns (ai_V, points_um), each ticks x 3")
      .def("truth", [](const pl::Twin& t) { return t.truth(); })
      .def("interferometer", [](const pl::Twin& t) { return t.interferometer(); })
      .def_property_readonly("fringe_piston_nm", &pl::Twin::fringe_piston_nm)
      .def_property_readonly("time_s", &pl::Twin::time_s)
      .def_property_readonly("ticks", &pl::Twin::ticks)
      .def_property_readonly("seed", &pl::Twin::seed)
      .def("set_fault", &pl::Twin::set_fault, py::arg("channel"), py::arg("fault"))
      .def("fault", &pl::Twin::fault, py::arg("channel"));
}

}  // namespace

void bind_twin_params(py::module_& m) {
  bind_actuation_params(m);
  bind_sensing_params(m);
  py::class_<pl::TwinParams>(m, "TwinParams")
      .def(py::init<>())
      .PS_RW(pl::TwinParams, physics_rate_Hz)
      .PS_RW(pl::TwinParams, daq)
      .PS_RW(pl::TwinParams, amplifier)
      .PS_RW(pl::TwinParams, piezo)
      .PS_RW(pl::TwinParams, contact)
      .PS_RW(pl::TwinParams, mechanics)
      .PS_RW(pl::TwinParams, plate)
      .PS_RW(pl::TwinParams, geometry)
      .PS_RW(pl::TwinParams, sgs)
      .PS_RW(pl::TwinParams, interferometer)
      .PS_RW(pl::TwinParams, lab)
      .PS_RW(pl::TwinParams, cavity);
  m.def("twin_params_problem", &pl::twin_params_problem, py::arg("design"), py::arg("twin"),
        "Why design and twin parameters cannot make a twin, or '' when they can");
}

void bind_twin(py::module_& m) {
  bind_twin_values(m);
  bind_twin_class(m);
}

}  // namespace piezoshift::python
