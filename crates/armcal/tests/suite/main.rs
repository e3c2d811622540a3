//! armcal's integration tests in one binary (it links the crate once), a module per area:
//! `cargo test -p armcal --test suite AREA::` runs one area, e.g. `design::`.

mod common;

mod model {
    mod cell_file;
    mod conversions;
    mod deploy;
    mod derivatives;
    mod export_reload;
    mod exports;
    mod fixed_kinematics;
    mod identifiability;
    mod robots;
    mod tree;
    mod urdf_tree;
}
mod identify {
    mod compliance;
    mod estimate_branch;
    mod estimate_checks;
    mod fitted_ranges;
    mod frames_first;
    mod frames_refit;
    mod honest_free_set;
    mod identification;
    mod identification_input;
    mod identification_validation;
    mod mixed_measurements;
    mod model_floor;
    mod payload;
    mod periodic;
    mod pivot;
    mod priors_and_noise;
    mod stations;
    mod tree;
}
mod campaign {
    mod adaptive;
    mod after_drift;
    mod drift;
}
mod design {
    mod clearance;
    mod design_bound;
    mod design_exchange;
    mod design_gradients;
    mod design_monte_carlo;
    mod design_plan;
    mod design_pool;
    mod design_refine;
    mod measurable;
    mod nongeometric_design;
    mod paper_cell_geometry;
    mod pose_design;
    mod tracker_shift;
    mod working_paths;
}
mod compensate {
    mod compensation;
    mod nonparametric;
}
mod book {
    mod book_checks;
    mod book_compensator;
    mod book_identification;
    mod study_puma;
}
mod files {
    mod read_back;
}
mod accuracy {
    mod iso9283_cubes;
}
mod real_data {
    mod motoman_calibration;
    mod motoman_nominal;
    mod motoman_nongeometric;
    mod motoman_tree;
    mod solver_convergence;
    mod ur10_cubes;
    mod ur10_import;
    mod ur10_nongeometric;
    mod ur10_stations;
}
mod hostile {
    mod cell_export_strings;
    mod cell_values;
    mod input_size;
    mod report_ranges;
    mod stations;
    mod urdf_collision_values;
    mod urdf_depth;
    mod urdf_parser_panic;
}
mod report {
    mod cell_view;
    mod decimation;
    mod html;
    mod tree;
    mod verdict;
}
mod repository {
    mod api_surface;
    mod builtin_cells;
    mod file_size;
    mod layering;
}
