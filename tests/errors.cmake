# Bad-input tests (issue #6): every case in tests/bad_inputs.py is one ctest. Each builds a
# broken mesh/scene/command line from the committed fixtures and requires exit code 2, stderr
# starting with "error:" and the key fact (file, group, key, element id, ...) in the message.
set(CONTACT3D_BAD_INPUT_CASES
  msh_truncated_ascii msh_truncated_ascii_elements msh_truncated_binary msh_truncated_binary_header
  msh_empty msh_not_a_mesh msh_missing_file msh_version_3 msh_version_4_0 msh_bad_coordinate
  msh_nan_coordinate msh_unknown_node msh_cubic_tet msh_hexahedron msh_inverted_tet
  msh_zero_volume_tet msh_inverted_tet_solve group_misspelt group_missing_traction group_misspelt_solve
  contact_not_in_plane gamma_u_empty gamma_u_group_empty gamma_u_group_empty_solve load_group_empty
  poisson_half poisson_above young_zero
  young_negative young_subnormal slip_bound_negative nan_young inf_poisson inf_slip_bound nan_traction nan_body_force
  nan_param overflowing_body_force overflowing_traction inf_cell_size nan_table_point nan_set_override inf_mesh_parameter unknown_key invalid_toml
  missing_scene stability_violation out_proc out_is_file out_under_file mesh_n_zero
  mesh_duplicate_tet mesh_duplicate_load_triangle mesh_duplicate_group_name mesh_initial_penetration
  mesh_contact_interior_face mesh_load_interior_face mesh_contact_not_a_face mesh_clamp_on_a_line mesh_huge_coordinate mesh_device_file
  scene_is_directory law_value_huge cli_no_scene cli_unknown_option cli_unknown_option_no_scene geo_system_call geo_include_outside
  geo_syntax_error_named_first refusal_does_not_cite_the_plate_warning mesh_cut_at_the_file_size_limit geo_parameter_unread mesh_n_without_generator mesh_parameters_with_a_file held_by_contact_on_one_cell_over_the_face held_by_contact_young_in_wrong_unit traction_entry_located
  medit_truncated medit_binary_truncated edp_system_call edp_script_fails
  displacement_missing_group displacement_rigid_motion_free held_by_contact_pulled_off check_pulled_off check_pulled_off_beside_a_prescribed_shear two_parts_one_floating_pulled_up held_by_contact_on_one_cell held_by_friction_too_weak
  held_by_contact_frictionless_pushed_sideways held_by_contact_coulomb_zero_pushed_sideways check_frictionless_pushed_sideways two_parts_one_floating two_parts_one_floating_no_contact
  mesh_hinged_block
  graded_cells_far_too_small cell_size_far_too_small cell_size_wrong_unit msh_one_partition_of_two serial_build_under_mpirun
  contact_normal_prescribed
  displacement_conflicting_values displacement_gradient_conflicting displacement_gradient_of_free_component
  pressure_without_value
  displacement_no_component pressure_on_volume_group material_region_not_volume
  friction_model_unknown coulomb_with_slip_bound friction_without_law contact_not_a_graph contact_folds_over
  plane_normal_away_from_body contact_all_clamped plane_point_far
  plane_normal_zero tilted_plane_penetration memory_factor_too_big check_memory_factor_too_big memory_blas_buffers memory_blas_worker_at_start out_empty mesh_output_empty schur_mumps_in_serial_build
  out_of_core_in_serial_build out_of_core_dir_missing check_schur_mumps_in_serial_build
  qp_rtol_per_err_negative fixed_point_tail_err_one fixed_point_variant_unknown tilted_plane_normal_huge path_with_nul overlapping_volumes contact_faces_one_above_another msh22_parametric_nodes
  msh_nul_in_section_header geo_fifo mesh_tets_overlap mesh_tet_inside_another mesh_tet_over_a_corner mesh_tet_outside_at_a_corner mesh_volumes_over_each_other mesh_clamped_triangle_not_a_face medit_binary_garbage
  medit_text_garbage)
foreach(case ${CONTACT3D_BAD_INPUT_CASES})
  add_test(NAME errors.${case}
    COMMAND ${CONTACT3D_PYTHON} ${CMAKE_SOURCE_DIR}/tests/bad_inputs.py --bin $<TARGET_FILE:contact3d>
            --source ${CMAKE_SOURCE_DIR} --case ${case})
  set_tests_properties(errors.${case} PROPERTIES TIMEOUT 120 LABELS errors)
endforeach()
# The list above must name every case the driver has (a forgotten case would go untested).
add_test(NAME errors.case_list_complete
  COMMAND ${CONTACT3D_PYTHON} ${CMAKE_SOURCE_DIR}/tests/check_case_list.py ${CMAKE_SOURCE_DIR}/tests/bad_inputs.py
          ${CMAKE_SOURCE_DIR}/tests/errors.cmake)

# `contact3d check` on a good scene: lists the groups with element counts and the tet quality.
add_test(NAME errors.check_command_reports
  COMMAND ${CONTACT3D_PYTHON} ${CMAKE_SOURCE_DIR}/tests/check_command.py --bin $<TARGET_FILE:contact3d>
          --source ${CMAKE_SOURCE_DIR})
set_tests_properties(errors.check_command_reports PROPERTIES TIMEOUT 120 LABELS errors)
