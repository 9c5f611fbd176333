# Every dependency is a Debian 12 package; scripts/install-deps installs them.
find_package(PkgConfig REQUIRED)
find_package(OpenGL REQUIRED COMPONENTS OpenGL EGL GLX)
# The OpenXR headers (libopenxr-dev): hmd.output "openxr". The loader (libopenxr-loader1) is
# opened at run time, only for that output; a headset's runtime (SteamVR, Monado, Varjo Base) is
# the loader's to find. Neither is needed to build or test.
find_package(OpenXR REQUIRED)
find_package(glfw3 3.3 REQUIRED)
find_package(X11 REQUIRED)  # the window's display lost: render::onDisplayLost
find_package(glm REQUIRED)
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(OpenCV 4.6 REQUIRED COMPONENTS core imgproc imgcodecs calib3d videoio aruco)
find_package(CLI11 REQUIRED)
find_package(nlohmann_json 3 REQUIRED)
find_package(OpenSSL REQUIRED)
find_package(ZLIB REQUIRED)
find_package(orocos_kdl REQUIRED)
# MuJoCo (libmujoco-dev): found by hand, because Debian 12's mujocoConfig.cmake names an include
# folder (libqhull_r) that no package installs, which stops CMake's generate step.
find_path(MUJOCO_INCLUDE_DIR mujoco/mujoco.h REQUIRED)
find_library(MUJOCO_LIBRARY mujoco REQUIRED)
add_library(arbci_mujoco INTERFACE)
target_include_directories(arbci_mujoco SYSTEM INTERFACE ${MUJOCO_INCLUDE_DIR})
target_link_libraries(arbci_mujoco INTERFACE ${MUJOCO_LIBRARY})
# LSL stream descriptions are XML and discovery queries are XPath: pugixml evaluates them as
# liblsl does (Debian libpugixml-dev).
find_package(pugixml REQUIRED)
# Amplifiers through eegdev (Debian libeegdev-dev; its plugins in eegdev-plugins-free). Found
# directly: its pkg-config file requires xdffileio's and libusb's development files.
find_library(EEGDEV_LIBRARY eegdev REQUIRED)
find_path(EEGDEV_INCLUDE_DIR eegdev.h REQUIRED)
pkg_check_modules(IMGUI REQUIRED IMPORTED_TARGET imgui)
pkg_check_modules(BIOSIG REQUIRED IMPORTED_TARGET libbiosig)
find_package(Threads REQUIRED)
find_path(EDFLIB_INCLUDE_DIR edflib.h REQUIRED)
find_library(EDFLIB_LIBRARY NAMES libedf.a edf REQUIRED)
if(ARBCI_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(ARBCI_BENCH)
  find_package(benchmark REQUIRED)
endif()
# libapriltag: the tracker's AprilTag kind (vision/), the synthetic scenes' tags and the
# benchmark's peer.
find_package(apriltag REQUIRED)
