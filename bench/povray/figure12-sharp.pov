// figure12-sharp.pov -- canonical scene "figure12-sharp" (the canonical scenes: bench/README.md and examples/):
// figure12 with every `Rounded r t` replaced by the sharp polyhedron of t.
// The unrounded baseline of Lobb's Table 1.  Plain CSG only.
// Coordinates are the spec's right-handed ones; the camera is mirrored
// (right -x*aspect, see common.inc).
#version 3.7;
#include "common.inc"

PeerCamera(<2.25, 3.2, 5.0>, <2.25, 0.5, -0.4>, 35)
PeerLight(<-3, 8, 6>)
PeerFloor()

#declare UnitCube = box { <0, 0, 0>, <1, 1, 1> }
#declare Box1 = box { <0.25, 0.8, 0.25>, <0.75, 1.3, 0.75> }   // y in [0.8,1.3]
#declare Box2 = box { <0.25, 0.8, 0.25>, <0.75, 1.8, 0.75> }   // y in [0.8,1.8]
#declare Box3 = box { <0.25, 1.0, 0.25>, <0.75, 1.5, 0.75> }   // y in [1.0,1.5]

// obj1 = SetDifference UnitCube box1
#declare Obj1 = difference { object { UnitCube } object { Box1 } }
// obj2 = SetDifference (Rounded r UnitCube) box1   -> sharp: same as obj1
#declare Obj2 = difference { object { UnitCube } object { Box1 } }
// obj3 = SetDifference UnitCube (Rounded r box2)   -> sharp: cube minus box2
#declare Obj3 = difference { object { UnitCube } object { Box2 } }
// obj4 = Rounded r (Difference UnitCube box1)      -> sharp: cube minus box1
//        (the density difference is -1 where box1 sticks out of the cube)
#declare Obj4 = difference { object { UnitCube } object { Box1 } }
// obj5 = Union (Rounded r UnitCube) (Rounded r box3) -> cube plus box3 on top
#declare Obj5 = union { object { UnitCube } object { Box3 } }
// obj6 = Rounded r (Sum UnitCube box3)             -> sharp: the same union
//        (the two boxes only share the face y = 1, so the sum is 0/1)
#declare Obj6 = union { object { UnitCube } object { Box3 } }

union {
  object { Obj1 translate <0,    0, -1.75> }
  object { Obj2 translate <1.75, 0, -1.75> }
  object { Obj3 translate <3.5,  0, -1.75> }
  object { Obj4 translate <0,    0,  0> }
  object { Obj5 translate <1.75, 0,  0> }
  object { Obj6 translate <3.5,  0,  0> }
  texture { ObjTex }
}
