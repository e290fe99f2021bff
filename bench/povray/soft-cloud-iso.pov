// soft-cloud-iso.pov -- canonical scene "soft-cloud N" (the canonical scenes: bench/README.md and examples/)
// as a POV-Ray isosurface of the exact Wyvill field summed over all keys:
//   F(p) = sum_k C(|p - c_k| / R),  C(x) = -4/9 x^6 + 17/9 x^4 - 22/9 x^2 + 1
// for x <= 1, 0 beyond; R = 0.6; surface F = 0.5, inside F > 0.5.
// POV-Ray's isosurface has no spatial structure for the keys: every function
// evaluation sums all N terms, so this is meant for N = 10 and 100 only.
// Run with Declare=N=10 or Declare=N=100 (default 1000 is slow).
// Coordinates are the spec's right-handed ones; the camera is mirrored
// (right -x*aspect, see common.inc).
// Declare=Report=1 prints POV-Ray's found gradient (see figure12.pov).
#version 3.7;
#include "common.inc"
#include "soft-cloud.inc"

// C as a function of u = (r/R)^2: a cubic for u < 1, 0 beyond (select(A, B,
// C) is B if A < 0 else C, and evaluates only the branch taken).
#declare WyvillU = function(pU) {
  select(pU - 1, ((-4/9 * pU + 17/9) * pU - 22/9) * pU + 1, 0)
}
#declare InvR2 = 1 / (KR * KR);

// The field: the #while loop below writes one term per key into the
// function's body (POV-Ray has no loops inside functions); each key's
// coordinates are constants.
#declare Lo = <1e9, 1e9, 1e9>;
#declare Hi = -Lo;
#declare Field = function {
  0
  #declare K = 0;
  #while (K < N)
    #declare C = Key(K);
    #declare Lo = <min(Lo.x, C.x), min(Lo.y, C.y), min(Lo.z, C.z)>;
    #declare Hi = <max(Hi.x, C.x), max(Hi.y, C.y), max(Hi.z, C.z)>;
    #declare Cx = C.x; #declare Cy = C.y; #declare Cz = C.z;   // floats: functions take no vectors
    + WyvillU(((x - Cx) * (x - Cx) + (y - Cy) * (y - Cy) + (z - Cz) * (z - Cz)) * InvR2)
    #declare K = K + 1;
  #end
}

// max_gradient: one key's steepest slope is max |dC/dr| = 1.583/R = 2.64
// (at r = 0.50 R, i.e. on an isolated key's surface); overlapping keys add.
// Values: 1.05 x POV-Ray's found maximum (Report=1): N = 10 found 5.532
// (at max_gradient 200), N = 100 found 4.394 (at max_gradient 20).
// Report=1 uses max_gradient 20 (not 200): N = 100 would take many minutes.
#ifndef (ReportMG) #declare ReportMG = 20; #end
#switch (N)
  #case (10)  #declare MG = MGChoice(5.81, 1); #break
  #case (100) #declare MG = MGChoice(4.61, 1); #break
  #else       #declare MG = MGChoice(4.0, 1);
#end

isosurface {
  function { -Field(x, y, z) }
  threshold -0.5
  // F > 0 only within R of a key
  contained_by { box { Lo - KR, Hi + KR } }
  max_gradient MG
  accuracy 0.001
  texture { ObjTex }
}
