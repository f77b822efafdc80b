"""The tests `make check` leaves out: conftest.py marks them ``slow`` (`make test` runs them).

A test is slow when it took 3 s or more of a worker's time in a full run on the 2-core machine
(``pytest -n 2 --durations=0``, while other work ran): the doc runs, the site, the notebooks,
the result scripts, the generated-input tests (tests/fuzz) and the corpus of bad command lines
whole; elsewhere the long physics runs and campaigns, the identification fits, the command-line
runs that write every output. The agreement of the compiled dynamics with the Python reference
and the first second of every shipped scenario stay in `make check` (they guard every change).

The order of the files: `make test` hands whole files to its two workers (pytest-xdist
``--dist loadfile``: a file's module- and session-scoped fixtures, the doc runs, the bad-input
corpus, run once, on one worker), in collection order; `longest_first` puts the long files
first, so that no worker ends the suite alone with a long file begun last.
"""

from __future__ import annotations

from collections.abc import Mapping

#: whole files, longest first: `make test`'s workers start them in this order (`longest_first`)
SLOW_MODULES = (
    "tests/test_docs_run.py",
    "tests/apps/validation/test_fit.py",
    "tests/test_docs_site.py",
    "tests/apps/cli/test_bad_inputs.py",
    "tests/test_make_results.py",
    "tests/test_notebooks.py",
    "tests/fuzz/",
)

#: module::function (every parameter of it)
SLOW_TESTS = frozenset(
    (
        "tests/physics/world/test_tumbling_boxes.py::test_the_python_reference_lands_the_same_boxes_without_stopping",
        "tests/scenario/test_valve_turn.py::test_the_valve_is_turned_a_quarter_turn_by_the_thrusters_push",
        "tests/scenario/test_valve_turn.py::test_a_push_budget_below_the_friction_leaves_the_valve_closed",
        "tests/scenario/test_hot_stab.py::test_the_stab_is_inserted_to_full_depth_the_chamfer_taking_the_aim_error",
        "tests/scenario/test_hot_stab.py::test_a_grip_too_weak_for_the_stab_drops_it_and_nothing_is_inserted",
        "tests/scenario/test_hot_stab.py::test_a_push_budget_too_small_leaves_the_stab_short_of_full_depth",
        "tests/scenario/test_cooperative_transport.py::test_two_robots_holding_the_bar_at_rest_share_its_net_weight_as_their_coefficients_say",
        "tests/scenario/test_fixtures.py::test_the_valve_panel_scenario_runs_stable_at_its_step",
        "tests/sim/test_robots_run.py::test_a_robot_grasps_the_first_robots_ball_as_a_single_robot_does",
        "tests/physics/world/test_alpha5_grasp.py::test_a_held_sample_adds_its_net_weight_to_the_force_the_vehicle_needs",
        "tests/apps/cli/test_run_robots.py::test_a_run_of_two_robots_writes_each_robots_results_and_a_block_each",
        # command-line runs and imports that write every output
        "tests/apps/cli/test_run_robots.py::test_the_progress_is_shown_unless_quiet",
        "tests/scenario/test_vehicle_only.py::test_a_vehicle_only_run_from_the_command_line",
        "tests/apps/cli/test_import_command.py::test_import_writes_the_urdf_and_the_table_and_says_what_it_did_not_map",
        "tests/scenario/test_object_recovery.py::test_the_sample_is_lifted_carried_and_placed_in_the_basket",
        "tests/scenario/test_shipped_steps.py::test_the_pushed_box_travels_as_at_half_the_step",
        "tests/scenario/test_object_recovery.py::test_a_grip_too_weak_for_the_sample_leaves_it_on_the_seabed",
        "tests/scenario/test_object_recovery.py::test_a_sample_past_the_grips_friction_limit_slips_out_on_the_lift",
        "tests/apps/viz/test_foxglove_live.py::test_a_running_simulation_is_streamed_at_real_time_as_it_runs",
        "tests/apps/viz/test_foxglove_live.py::test_uvms_pin_replay_live_foxglove_waits_for_a_client_and_sends_the_whole_run",
        "tests/apps/arms/test_compare.py::test_keep_rollouts_writes_each_arms_outputs",
        "tests/apps/cli/test_cli.py::test_run_passive_scenario_writes_rollout_metrics_and_figures",
        "tests/apps/cli/test_compare_controllers.py::test_a_tracking_comparison_says_when_the_run_ends_before_its_transient",
        "tests/apps/cli/test_compare_controllers.py::test_compare_controllers_short_run",
        "tests/apps/cli/test_compare_controllers.py::test_robustness_set_through_the_study_runner",
        "tests/apps/cli/test_export_command.py::test_export_writes_a_bag_the_reader_opens",
        "tests/apps/cli/test_run_outputs.py::test_a_second_ctrl_c_while_saving_does_not_lose_the_rollout",
        "tests/apps/cli/test_run_outputs.py::test_ctrl_c_keeps_the_partial_rollout_and_a_second_run_into_its_out_is_refused",
        "tests/apps/cli/test_run_outputs.py::test_overwrite_replaces_a_runs_outputs_keeps_the_users_files_and_follows_the_umask",
        "tests/apps/cli/test_study_directory.py::test_a_study_directory_refuses_another_study_and_a_changed_base",
        "tests/apps/cli/test_study_directory.py::test_ctrl_c_on_a_parallel_sweep_prints_one_message_and_the_rerun_finishes",
        "tests/apps/study/test_study_runner.py::test_booleans_and_strings_are_swept_and_reported",
        "tests/apps/study/test_study_runner.py::test_killing_the_sweep_process_and_rerunning_finishes_the_study",
        "tests/apps/study/test_study_runner.py::test_report_writes_markdown_and_figures",
        "tests/apps/validation/test_identify.py::test_from_kolanos_centre_of_buoyancy_the_cli_finds_the_shipped_correction",
        "tests/apps/validation/test_identify.py::test_the_shipped_cob_shift_is_the_fit_on_the_identification_trials",
        "tests/apps/validation/test_imu_mount.py::test_fit_jacobian_in_imu_yaw_and_damping_matches_finite_differences",
        "tests/apps/validation/test_imu_mount.py::test_validate_pool_takes_the_imu_yaw_in_degrees",
        "tests/apps/validation/test_pool.py::test_no_figures_says_so",
        "tests/apps/validation/test_pool.py::test_short_trials_meet_the_targets",
        "tests/apps/validation/test_pool.py::test_writes_json_exactly_as_specified_csv_and_figures",
        "tests/apps/viz/test_live_server.py::test_a_browser_receives_the_stream_paced_by_the_clock",
        "tests/apps/viz/test_live_server.py::test_cli_busy_port_exits_with_a_clear_message",
        "tests/apps/viz/test_live_server.py::test_cli_ctrl_c_during_a_live_run_shuts_the_server_down",
        "tests/apps/viz/test_live_server.py::test_cli_live_run_equals_plain_run_and_shuts_down",
        "tests/apps/viz/test_meshcat_scene.py::test_show_model_script_runs_headless",
        "tests/apps/viz/test_replay_browser.py::test_the_page_renders_the_vehicle_and_its_animation_moves",
        "tests/control/test_mpc.py::test_mpc_holds_station_with_csqp_or_rk4_nodes_deterministically",
        "tests/control/test_mpc_campaign.py::test_mpc_runs_end_to_end_shortened_and_twice_bit_for_bit",
        "tests/flow/test_flow_core.py::test_the_sea_state_closed_loop_is_the_same_on_both_backends",
        "tests/model/importer/test_imported_vehicle_runs.py::test_the_imported_lrauv_with_passive_fins_runs_a_minute_or_is_refused",
        "tests/model/importer/test_imported_vehicle_runs.py::test_the_imported_lrauv_with_lifting_fins_runs_a_minute_and_its_fins_only_take_energy",
        "tests/model/importer/test_imported_vehicle_runs.py::test_the_imported_lrauv_steers_with_its_rudder_held_as_a_joint",
        "tests/model/test_mount.py::test_compare_arms_runs_the_force_task",
        "tests/ocp/test_csqp.py::test_csqp_keeps_station_with_saturated_thrusters_like_boxfddp",
        "tests/ocp/test_node_errors.py::test_an_error_in_a_node_reaches_the_caller_of_solve",
        "tests/perception/test_loop.py::test_the_visual_approach_presses_the_jaw_on_the_ball",
        "tests/perception/test_survey.py::test_the_multibeam_soundings_lie_on_the_seabed_and_on_the_crate",
        # the survey run's other test (left in `make check`, it kept the run there)
        "tests/perception/test_survey.py::test_the_dvl_loses_its_lock_over_the_crate_only_and_the_estimate_goes_on",
        "tests/physics/constraints/test_object_contacts.py::test_the_compiled_period_is_the_python_reference_to_the_solvers_tolerance",
        "tests/physics/derivatives/test_derivatives_campaign.py::test_random_states_match_finite_differences_and_the_core",
        "tests/physics/test_core.py::test_realistic_closed_loop_matches_the_python_reference_over_2_s",
        "tests/physics/test_derivatives_surface.py::test_cut_hulls_match_finite_differences",
        "tests/physics/test_self_collision.py::test_an_arm_folded_into_the_hull_is_pushed_out_only_on_request",
        "tests/physics/test_world_compiled.py::test_runs_that_stick_slide_and_rebound_are_the_reference",
        "tests/physics/test_world_contact.py::test_a_block_on_a_slope_gentler_than_its_friction_stays_put",
        "tests/physics/test_world_contact.py::test_a_block_on_a_steep_slope_slides_at_the_coulomb_acceleration",
        "tests/physics/test_world_contact.py::test_a_box_rests_on_the_seafloor_with_its_net_weight_and_does_not_sink",
        "tests/physics/test_world_contact.py::test_a_dropped_sphere_rebounds_as_the_contact_damping_says",
        "tests/physics/test_world_contact.py::test_a_sphere_rests_on_a_box_object_through_coal",
        "tests/results/test_outdir.py::test_run_outputs_are_exactly_the_files_a_run_writes",
        "tests/scenario/test_mpc_scenario.py::test_a_bad_mpc_horizon_exits_2_on_the_command_line",
        "tests/scenario/test_mpc_scenario.py::test_mpc_force_tracking_holds_the_force_and_is_deterministic",
        "tests/scenario/test_mpc_scenario.py::test_mpc_station_keeping_holds_the_pose_and_is_deterministic",
        "tests/scenario/test_mpc_scenario.py::test_mpc_station_keeping_in_a_sea_holds_the_pose",
        "tests/scenario/test_mpc_scenario.py::test_the_force_mpc_on_a_wrong_model_still_tracks",
        "tests/scenario/test_mpc_scenario.py::test_the_force_mpc_tracks_with_csqp",
        "tests/scenario/test_overrides.py::test_run_set_from_the_command_line",
        "tests/sim/estimation/test_eskf.py::test_nees_is_chi_square_over_monte_carlo_seeds",
        # the Monte Carlo runs' other test (left in `make check`, it kept their fixture there)
        "tests/sim/estimation/test_eskf.py::test_errors_are_within_three_sigma_and_position_is_usbl_bounded",
        "tests/sim/estimation/test_eskf.py::test_dropouts_grow_the_covariance_and_keep_the_filter_consistent",
        "tests/sim/estimation/test_eskf.py::test_biases_on_a_still_vehicle",
        "tests/sim/estimation/test_estimator_in_the_loop.py::test_the_shipped_scenario_holds_its_station_on_the_estimate",
        "tests/sim/test_closed_loop.py::test_cli_saves_and_plots_the_partial_rollout",
        "tests/sim/test_closed_loop.py::test_paper_scenario_holds_its_funnels",
        # the paper's claim campaign (+-30 % plant) and the integration tolerance's convergence
        "tests/sim/test_closed_loop.py::test_paper_funnels_hold_with_plant_parameters_off_by_30_percent",
        "tests/sim/test_closed_loop.py::test_paper_force_trajectory_converges_with_the_tolerance",
        "tests/sim/test_compiled_system.py::test_push_object_compiled_follows_the_python_integration",
        "tests/sim/test_continuous_joints_run.py::test_backends_agree_on_a_continuous_run_through_the_free_surface",
        "tests/sim/test_shortened.py::test_the_command_line_prints_it",
        "tests/sim/test_simulate.py::test_cli_exits_3_and_saves_the_partial_rollout_of_a_blow_up",
        "tests/sim/test_stable_defaults.py::test_the_limits_solved_in_the_core_are_the_python_loops",
        "tests/test_docs.py::test_nothing_points_to_notes_outside_the_repository",
    )
)


#: the files of single runs of a minute or more (CPU, serial), longest first: after the
#: `SLOW_MODULES` in `longest_first`'s order
LONG_FILES = (
    "tests/scenario/test_hot_stab.py",
    "tests/scenario/test_cooperative_transport.py",
    "tests/scenario/test_valve_turn.py",
)


def longest_first(path: str, slow_in_file: Mapping[str, int]) -> tuple[int, int]:
    """The sort key of a test file (``tests/...py``) in the run: the `SLOW_MODULES`, then the
    `LONG_FILES`, in their order, then the files holding the most slow tests
    (``slow_in_file``), then the rest (a stable sort keeps the collection order among equals
    and the tests of a file together)."""
    for index, prefix in enumerate(SLOW_MODULES + LONG_FILES):
        if path.startswith(prefix):
            return (index, 0)
    return (len(SLOW_MODULES) + len(LONG_FILES), -slow_in_file.get(path, 0))
