// soft-cloud.pov -- canonical scene "soft-cloud N" (the canonical scenes: bench/README.md and examples/)
// as a POV-Ray blob: one spherical component per key, radius R = 0.6,
// strength 1.  Run with Declare=N=10 (100, 1000, 10000; default 1000).
//
// POV-Ray's blob field is not Wyvill's: a component contributes
// strength * (1 - (r/R)^2)^2 (Wyvill: -4/9 x^6 + 17/9 x^4 - 22/9 x^2 + 1,
// x = r/R).  The threshold is chosen so that an isolated key gives a sphere
// of the same radius as Wyvill's field at 0.5: Wyvill's C(x) = 0.5 has the
// root x^2 = 1/4 exactly (4u^3 - 17u^2 + 22u - 4.5 = 0 at u = 1/4), i.e. the
// isolated radius is R/2 = 0.3; POV-Ray's field there is (1 - 1/4)^2 =
// 0.5625, the threshold.  Where keys overlap the two fields differ, so the
// blended shapes differ slightly (see README.md).
// Coordinates are the spec's right-handed ones; the camera is mirrored
// (right -x*aspect, see common.inc).
#version 3.7;
#include "common.inc"
#include "soft-cloud.inc"

blob {
  threshold 0.5625
  #declare K = 0;
  #while (K < N)
    sphere { Key(K), KR, strength 1 }
    #declare K = K + 1;
  #end
  texture { ObjTex }
}
