"""Which test runs each command line option and checks that it reaches the library.

``test_every_option_is_wired.py`` walks every parser of ``cyclecoord`` (``build_parser``)
and fails for an option missing here, an entry naming an option that no longer exists, or
a test that does not exist or whose file never spells the option or the command.

To register a new option: write a test that runs the command with it and checks what the
library receives (``tests/cli/test_wiring.py``: put a :class:`Spy` on the function the
option is for, or check the written output), then add a line under its command here::

    "extract": {
        ...
        "--feet": "tests/quality/test_feet.py::test_feet_option_reaches_foot_contacts",
    },

An option any of whose spellings is a key counts (``-o`` for ``-o/--output``).  A value is
one test or a tuple of tests, each ``path::function`` from the checkout's root.
"""

W = "tests/cli/test_wiring.py::"
ANALYSIS = W + "test_analysis_options_reach_the_pipeline"
READER = W + "test_skeleton_and_fps_reach_the_reader"
BARCODE = W + "test_barcode_options_reach_preparation_and_filtration"
RENDER = W + "test_render_options_reach_render"
MATCHING = W + "test_matching_options_reach_blend_and_transition"
AS_CYCLE = W + "test_input_options_reach_as_cycle"
BATCH = W + "test_batch_options_reach_run_batch"
GRAPH = (W + "test_graph_options_reach_the_synthesiser",
         W + "test_graph_crossval_options_reach_cross_validate")
GRAPH_WALK = W + "test_graph_start_target_and_frames_reach_the_walk"
LATENT = W + "test_latent_fit_options_reach_the_model"
FEET = W + "test_feet_reach_the_library"
UNITS = W + "test_units_reach_the_gltf_and_usd_writers"
MEMORY = W + "test_memory_limit_reaches_the_readers"
CLI = "tests/cli/test_cli.py::"
BLEND = "tests/cli/test_cli_blend.py::"

#: command -> option -> the test(s) that run it and check it arrives
WIRED: dict[str, dict[str, str | tuple[str, ...]]] = {
    "": {"--version": W + "test_version_prints_the_package_version"},
    "extract": {
        "--skeleton": READER,
        "--frames": ANALYSIS,
        "--fps": READER,
        **dict.fromkeys(("--pca", "--normalize", "--rotations", "--temporal", "--no-root-diff",
                         "--prime", "--max-scale", "--landmarks", "--memory-limit", "--scale",
                         "--class", "--samples", "--neighbors", "--weighting", "--sampling",
                         "--seed", "--delay", "--no-steady", "--timing", "--travel",
                         "--min-turns", "--bandwidth", "--cycle-start"), ANALYSIS),
        "-v": W + "test_verbose_adds_barcode_class_and_timings",
        "-o": CLI + "test_extract_example_writes_cycle_and_report",
        "--report": CLI + "test_extract_example_writes_cycle_and_report",
        "--plot": "tests/plot/test_plot.py::test_cli_extract_plot_and_render_side_by_side",
        "--lock-feet": CLI + "test_extract_lock_feet_writes_a_cycle_whose_feet_stay",
        "--save-model": "tests/periodic/test_landmarks.py::test_cli_save_and_apply",
        "--apply": "tests/periodic/test_landmarks.py::test_cli_save_and_apply",
        "--units": UNITS,
        "--feet": FEET,
    },
    "barcode": {
        "--skeleton": READER,
        "--fps": READER,
        "--frames": W + "test_barcode_frames_window_the_motion",
        **dict.fromkeys(("--pca", "--normalize", "--rotations", "--temporal", "--no-root-diff",
                         "--prime", "--max-scale", "--landmarks", "--memory-limit"), BARCODE),
        "--json": CLI + "test_barcode_json",
    },
    "convert": {
        "--memory-limit": MEMORY,
        "-o": CLI + "test_convert_round_trip_and_refuses_to_overwrite",
        "--skeleton": READER,
        "--fps": READER,
        "--frames": W + "test_convert_frames_reach_the_written_motion",
        "--units": UNITS,
    },
    "detect": {
        "--skeleton": READER,
        "--fps": READER,
        **dict.fromkeys(("--frames", "--pca", "--normalize", "--rotations", "--temporal",
                         "--no-root-diff", "--prime", "--max-scale", "--landmarks",
                         "--memory-limit", "--classes", "--delay", "--method", "--no-progress"),
                        ANALYSIS),
        "--report": "tests/periodic/test_detect.py::test_cli_detect",
        "--extract": "tests/periodic/test_detect.py::test_cli_detect",
        "--plot": "tests/periodic/test_detect.py::test_cli_detect",
        **dict.fromkeys(("--timing", "--travel", "--bandwidth", "--cycle-start"),
                        W + "test_detect_cycle_options_reach_motion_cycles"),
        "--extract-format": W + "test_detect_extract_format_names_the_cycles_written",
        "--feet": FEET,
    },
    "render": {
        "-o": "tests/plot/test_plot.py::test_cli_extract_plot_and_render_side_by_side",
        "--skeleton": READER,
        "--fps": READER,
        "--frames": W + "test_render_frames_and_side_by_side",
        "--side-by-side": W + "test_render_frames_and_side_by_side",
        "--step": RENDER,
        "--view": RENDER,
        "--follow": RENDER,
        "--no-progress": W + "test_render_no_progress_reaches_render",
    },
    **{command: {
        **dict.fromkeys(("--as-cycle", "--extract", "--window", "--fps", "--max-scale",
                         "--scale", "--seed"), AS_CYCLE),
        **dict.fromkeys(("--allow-reverse", "--no-heading", "--up"), MATCHING),
        "--margin": W + "test_margin_reaches_the_plausibility_check",
        "--feet": FEET,
    } for command in ("blend", "transition")},
    "batch": {
        **dict.fromkeys(("-o", "-j", "--scheduler", "--force", "--pattern", "--cycles",
                         "--no-progress", "--fps", "--pca", "--normalize", "--rotations",
                         "--temporal", "--prime", "--max-scale", "--landmarks", "--memory-limit",
                         "--seed", "--no-steady", "--timing", "--travel", "--min-turns",
                         "--bandwidth", "--cycle-start"), BATCH),
        "--feet": FEET,
    },
    "view": {
        "--memory-limit": MEMORY,
        "-o": W + "test_view_writes_the_page",
        "--skeleton": READER,
        "--fps": READER,
        **dict.fromkeys(("--side-by-side", "--frames", "--other-frames", "--cycle",
                         "--other-cycle", "--max-fps", "--no-contacts"),
                        W + "test_view_options_reach_the_figure"),
        "--feet": FEET,
    },
    "feet": {
        "--memory-limit": MEMORY,
        "--skeleton": READER,
        "--fps": READER,
        "--units": UNITS,
        "--feet": FEET,
        **dict.fromkeys(("--height", "--speed", "--skate-speed"),
                        W + "test_feet_thresholds_reach_contacts_and_skating"),
        **dict.fromkeys(("--frames", "--cycle"), W + "test_feet_frames_cycle_and_lock_reach_lock_feet"),
        **dict.fromkeys(("--lock", "-o", "--report"),
                        W + "test_feet_lock_writes_the_locked_motion_and_the_report"),
    },
    "graph": {
        "--memory-limit": MEMORY,
        **dict.fromkeys(("--method", "--dims", "-k", "--integrator", "--step-scale"), GRAPH),
        **dict.fromkeys(("--start", "--target", "--frames"), GRAPH_WALK),
        **dict.fromkeys(("-o", "--report", "--plot"),
                        "tests/synthesis/test_graph_cli.py::test_generate_writes_motion_report_and_figures"),
        "--strict": W + "test_graph_strict_refuses_an_implausible_motion",
        "--allow-contacts": W + "test_graph_refuses_limbs_through_each_other_unless_allowed",
        "--no-topo": W + "test_graph_crossval_options_reach_cross_validate",
        **dict.fromkeys(("--no-carry", "--no-lock"),
                        W + "test_graph_carry_and_lock_reach_the_synthesiser"),
        "--horizon": W + "test_graph_horizon_and_no_progress_reach_cross_validate",
        "--fps": (W + "test_graph_fps_reaches_the_takes",
                  "tests/synthesis/test_graph_cli.py::"
                  "test_takes_at_a_whole_multiple_of_the_rate_are_taken_every_kth_frame"),
        "--no-progress": (W + "test_graph_horizon_and_no_progress_reach_cross_validate",
                          W + "test_graph_no_progress_reaches_the_loading_bar"),
    },
    "latent fit": {
        "--memory-limit": MEMORY,
        **dict.fromkeys(("--dims", "--variance", "--step", "--max-iter"), LATENT),
        **dict.fromkeys(("-o", "--report"), W + "test_latent_fit_writes_the_model_and_the_report"),
        "--no-progress": W + "test_latent_fit_no_progress_reaches_fit",
        "--fps": W + "test_latent_fit_fps_reaches_the_takes",
        "--step": (LATENT, W + "test_latent_fit_default_step_trains_near_30_fps"),
    },
    "animate": {
        "--memory-limit": MEMORY,
        **dict.fromkeys(("-o", "--report"), "tests/synthesis/test_latent_cli.py::"
                        "test_animate_writes_bvh_and_report_reproducibly"),
        "--no-check": W + "test_animate_no_check_reaches_run_script",
        "--allow-contacts": W + "test_animate_refuses_limbs_through_each_other_unless_allowed",
        "--feet": W + "test_animate_feet_reach_the_script",
        "--no-progress": W + "test_animate_no_progress_reaches_run_script",
    },
}

# the two commands' own options
WIRED["blend"] |= {
    "--weights": BLEND + "test_blend_writes_a_loop_and_a_report",
    "--strict": BLEND + "test_strict_refuses_an_implausible_blend",
    "-o": BLEND + "test_blend_writes_a_loop_and_a_report",
    "--report": BLEND + "test_blend_writes_a_loop_and_a_report",
}
WIRED["transition"] |= {
    **dict.fromkeys(("--frames", "--cycles", "--lead-in", "--lead-out"),
                    W + "test_transition_length_options_reach_transition"),
    "--strict": BLEND + "test_transition_too_short_is_refused_under_strict",
    "-o": BLEND + "test_transition_writes_a_continuous_clip",
    "--report": BLEND + "test_transition_writes_a_continuous_clip",
}
