// figure15a.pov -- canonical scene "figure15a" (canonical scene, see examples/; Lobb,
// Figure 15(a)): different radii on different planes of one cuboid.
// The cuboid [0,2] x [0,1] x [0,1] is the product of six density halfspaces:
// x = 0, x = 2, z = 0, z = 1 with r = 0.3; y = 0, y = 1 with r = 0.03.
// Shift (1.25, 0, -0.5) moves the planes (the radii are unchanged), so the
// cuboid is [1.25,3.25] x [0,1] x [-0.5,0.5], on the floor.
// Coordinates are the spec's right-handed ones; the camera is mirrored
// (right -x*aspect, see common.inc).
// Declare=Report=1 prints POV-Ray's found gradient (see figure12.pov).
#version 3.7;
#include "common.inc"

PeerCamera(<3.5, 2.6, 4.0>, <2.25, 0.5, 0>, 35)
PeerLight(<-3, 8, 6>)
PeerFloor()

#declare RSide = 0.3;
#declare RTop  = 0.03;
#declare M     = 0.01;                      // container margin

#declare DCuboid = function {
  LobbSlab(x, 1.25, 3.25, RSide) * LobbSlab(y, 0, 1, RTop) * LobbSlab(z, -0.5, 0.5, RSide)
}

// max_gradient: the steepest factor is a top/bottom plane, 3/(4*0.03) = 25
// (slope along the plane normal).  POV-Ray measures slopes along the rays it
// traces; it found 17.05 (Report=1; about 25 x 0.68, and the shadow rays
// to the light make cos ~0.66-0.68 with the top face's normal) and calls 25
// too high, so the value is 1.05 x found.
#declare MG = MGChoice(17.9, 1);

isosurface {
  function { -DCuboid(x, y, z) }
  threshold -0.5
  // a product of [0,1] densities lies inside the sharp cuboid (Theorem 1)
  contained_by { box { <1.25 - M, -M, -0.5 - M>, <3.25 + M, 1 + M, 0.5 + M> } }
  max_gradient MG
  accuracy 0.001
  texture { ObjTex }
}
