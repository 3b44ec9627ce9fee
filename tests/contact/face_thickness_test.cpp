// FaceThickness (solver/contact/face_thickness.*): the body's thickness above Γc by vertical rays to
// its upward boundary faces, against bricks whose tops are known planes, and the contact triangles'
// element size.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "contact/face_thickness.hpp"
#include "mesh/brick_generator.hpp"

using namespace contact3d;

TEST(FaceThickness, AFlatPlateIsItsThicknessEverywhere) {
  const Mesh plate = make_paper_brick({4, 3.0, 1.0, 0.02});  // 12 x 4 cubes of 0.25 in the plane
  const FaceThickness t = measure_face_thickness(plate, {"contact"});
  EXPECT_EQ(t.triangles, t.measured);
  EXPECT_GT(t.triangles, 0);
  EXPECT_NEAR(t.median, 0.02, 1e-14);
  EXPECT_NEAR(t.element_size, 0.25, 1e-14);
  EXPECT_NEAR(t.extent, 3.0, 1e-14);  // the longer side of the body in the plane: the span a plate bends over
}

// The top tilted to z = 0.1 (1 + x) over x in [0, 3]: the thickness at a triangle's centroid is that
// plane's height there (P1 faces reproduce a plane exactly), so the area-weighted median is the
// height at the median x = 1.5 to within a triangle's width.
TEST(FaceThickness, ATiltedTopGivesTheHeightOverTheMedianPoint) {
  Mesh brick = make_paper_brick({4, 3.0, 1.0, 0.1});
  for (Eigen::Vector3d& x : brick.nodes) x.z() *= 1 + x.x();
  const FaceThickness t = measure_face_thickness(brick, {"contact"});
  EXPECT_EQ(t.triangles, t.measured);
  EXPECT_NEAR(t.median, 0.1 * 2.5, 0.1 * 0.25);
}

// A sole lifted above the plane (an initial gap) does not count: the thickness is measured from Γc
// itself, up to the first face above it; the faces below Γc or beside it are not in the way.
TEST(FaceThickness, IsMeasuredFromTheContactFaceNotFromThePlane) {
  Mesh brick = make_paper_brick({4});
  for (Eigen::Vector3d& x : brick.nodes) x.z() = 0.5 + 0.3 * x.z();  // 0.3 thick, lifted by 0.5
  const FaceThickness t = measure_face_thickness(brick, {"contact"});
  EXPECT_NEAR(t.median, 0.3, 1e-12);
}

TEST(FaceThickness, AMissingGroupIsAnInputError) {
  const Mesh brick = make_paper_brick({2});
  EXPECT_ANY_THROW(measure_face_thickness(brick, {"no_such_group"}));
}
