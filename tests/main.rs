//! The integration tests, one module per file, built as one test binary (`cargo test
//! --release --test integration`; one file's tests: `... --test integration paper::`).
//! One binary links the solver once instead of once per file, which is most of the build.
//! Tests of different files run at the same time, so each writes under a directory of its
//! own (`common::fresh_dir` puts the calling file's name in the path).

mod common;

mod adjust;
mod block_die;
mod bracket;
mod cli;
mod communication;
mod consistent_tangent;
mod contact;
mod contact_cli;
mod contact_pressure;
mod cycles;
mod examples;
mod exodus;
mod exodus_mesh;
mod extreme;
mod file_safety;
mod file_size;
mod foundation;
mod friction_dirichlet;
mod friction_symmetry;
mod general_contact;
mod gmsh;
mod gmsh_tags;
mod gmsh_tet;
mod hertz_mortar;
mod hertz_tet;
mod integrity;
mod ironing;
mod layering;
mod limit_load;
mod mean_bending;
mod mean_folded;
mod mean_patch;
mod memory;
mod mortar_patch;
mod multilevel;
mod operator_export;
mod outline;
mod output;
mod output_header;
mod output_post;
mod paper;
mod paraview;
mod penetration_audit;
mod plastic_bar;
mod plastic_kernel;
mod plastic_large;
mod plastic_punch;
mod plastic_restart;
mod plastic_scene;
mod plastic_sphere;
mod plastic_sphere_tet;
mod preconditioner;
mod restart;
mod restart_kills;
mod restart_layout;
mod self_contact;
mod tangent_preconditioner;
mod tet10_kernel;
mod tet10_solve;
mod tet_contact;
mod tet_gmsh_solve;
