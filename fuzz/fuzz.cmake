# libFuzzer targets, built by scripts/fuzz.sh in its own build directory with
# clang, -DSTC_FUZZ=ON and ASan + UBSan + fuzzer-no-link in CMAKE_CXX_FLAGS
# (so stc_core is instrumented too). fuzz/fuzz_NAME.cpp -> executable fuzz_NAME.
# Requests and scene files (stc_scene, ROS-free) and the two files of src/ros
# they meet (message conversion, package:// resolution) are compiled in
# directly: no node, no ROS master.
add_library(stc_fuzz_ros STATIC
  ${PROJECT_SOURCE_DIR}/src/ros/conversions.cpp
  ${PROJECT_SOURCE_DIR}/src/ros/mesh_resource.cpp)
target_include_directories(stc_fuzz_ros PUBLIC ${PROJECT_SOURCE_DIR}/include ${PROJECT_SOURCE_DIR}/src/ros/include)
target_link_libraries(stc_fuzz_ros stc_core stc_core_internal stc_scene ${catkin_LIBRARIES})
# Mesh entities: assimp loading and package:// resolution.
target_link_libraries(stc_fuzz_ros stc_mesh ${roslib_LIBRARIES})
target_include_directories(stc_fuzz_ros SYSTEM PRIVATE ${roslib_INCLUDE_DIRS})
add_dependencies(stc_fuzz_ros ${PROJECT_NAME}_generate_messages_cpp)

file(GLOB STC_FUZZ_TARGETS CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/fuzz/fuzz_*.cpp)
foreach(src ${STC_FUZZ_TARGETS})
  get_filename_component(name ${src} NAME_WE)
  add_executable(${name} ${src})
  target_link_libraries(${name} stc_fuzz_ros)
  target_link_options(${name} PRIVATE -fsanitize=fuzzer)
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/fuzz)
endforeach()
