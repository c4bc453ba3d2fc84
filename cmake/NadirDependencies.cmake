# Every dependency comes from Debian 12 packages (scripts/debian-packages.txt).
find_package(PkgConfig REQUIRED)

# Debian's LCM 1.3.1 ships only a pkg-config file (which needs glib-2.0.pc).
pkg_check_modules(LCM REQUIRED IMPORTED_TARGET lcm)
find_program(LCM_GEN_EXECUTABLE lcm-gen REQUIRED)

pkg_check_modules(GEOGRAPHICLIB REQUIRED IMPORTED_TARGET geographiclib)
pkg_check_modules(YAMLCPP REQUIRED IMPORTED_TARGET yaml-cpp)
pkg_check_modules(EGL REQUIRED IMPORTED_TARGET egl)
pkg_check_modules(LIBTIFF REQUIRED IMPORTED_TARGET libtiff-4)
# Terrain files in any format and CRS (CMake's FindGDAL; PROJ comes with it).
find_package(GDAL 3.6 REQUIRED)
pkg_check_modules(OPENGL REQUIRED IMPORTED_TARGET opengl)

find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(CLI11 REQUIRED)
find_package(Threads REQUIRED)
find_package(nlohmann_json 3 REQUIRED)

# Found here only to report their versions in `nadir doctor`; later libraries link them.
find_package(OpenCV 4 QUIET COMPONENTS core)
find_package(Qt6 QUIET COMPONENTS Core)
