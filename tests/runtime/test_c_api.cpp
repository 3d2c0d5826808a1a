// Driver of test_c_api.c: the C API exercised from C11 code (compiled as C, linked here).
#include <gtest/gtest.h>

#include <cstddef>

extern "C" {
int prt_c_check_errors(char* msg, size_t size);
int prt_c_check_shading(char* msg, size_t size);
int prt_c_check_fiv(char* msg, size_t size);
int prt_c_check_glossy(char* msg, size_t size);
int prt_c_check_lights(char* msg, size_t size);
}

namespace {

TEST(CApi, StatusesMessagesAndArgumentErrors) {
  char msg[512] = "";
  EXPECT_EQ(prt_c_check_errors(msg, sizeof msg), 0) << msg;
}

TEST(CApi, ProjectionTransferBand1Rotation) {
  char msg[512] = "";
  EXPECT_EQ(prt_c_check_shading(msg, sizeof msg), 0) << msg;
}

TEST(CApi, FivSceneShading) {
  char msg[512] = "";
  EXPECT_EQ(prt_c_check_fiv(msg, sizeof msg), 0) << msg;
}

TEST(CApi, GlossyShadingBothRoutes) {
  char msg[512] = "";
  EXPECT_EQ(prt_c_check_glossy(msg, sizeof msg), 0) << msg;
}

TEST(CApi, BakedLightsPunctualAndLtc) {
  char msg[512] = "";
  EXPECT_EQ(prt_c_check_lights(msg, sizeof msg), 0) << msg;
}

} // namespace
