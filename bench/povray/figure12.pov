// figure12.pov -- canonical scene "figure12" (canonical scene, see examples/; Lobb,
// "Quasi-Convolutional Smoothing of Polyhedra", Figures 11 and 12).
// Rounded objects are POV-Ray isosurfaces whose function is exactly Lobb's
// density (common.inc: LobbHS, LobbBox); sharp parts are plain CSG; the two
// are combined with CSG exactly as in the spec.
// Coordinates are the spec's right-handed ones; the camera is mirrored
// (right -x*aspect, see common.inc).
//
// Tuning: render with Declare=Tune=1 to replace each CSG difference by its
// isosurface operand alone.  POV-Ray 3.7.0 prints its "maximum gradient
// found" report only for isosurfaces that are not inside a difference, and
// only for an isosurface that is not a copy (so the objects below are macros,
// not #declare'd objects).
#version 3.7;
#include "common.inc"

PeerCamera(<2.25, 3.2, 5.0>, <2.25, 0.5, -0.4>, 35)
PeerLight(<-3, 8, 6>)
PeerFloor()

#declare Rr = 0.07;                         // r
#declare M  = 0.01;                         // container margin

// max_gradient.  The steepest slope of one smoothed halfspace is
// |d rho / d dist| = 3/(4r) (at the plane); a product of [0,1] factors of one
// radius is no steeper, nor is the Sum below (its terms' slopes oppose where
// they overlap).  In the Difference the cube's top plane and box1's side
// planes act together at the rim of the hole: sqrt(2) * 3/(4r).
// POV-Ray's reports (Report=1 Tune=1, README.md) agree: found 10.21-10.44
// for the products and the Sum, 14.75 for the Difference, and no warning is
// printed for the values below.
// Declare=Report=1 (with Tune=1) sets every max_gradient to 200.k instead,
// so that POV-Ray prints the gradient it found for each (labelled by k).
#declare MGHS  = 3 / (4 * Rr);              // 10.714
#declare MG2  = MGChoice(MGHS, 2);          // obj2: rounded UnitCube
#declare MG3  = MGChoice(MGHS, 3);          // obj3: rounded box2
#declare MG4  = MGChoice(sqrt(2) * MGHS, 4);// obj4: Difference UnitCube box1 (15.15)
#declare MG5a = MGChoice(MGHS, 5);          // obj5: rounded UnitCube
#declare MG5b = MGChoice(MGHS, 6);          // obj5: rounded box3
#declare MG6  = MGChoice(MGHS, 7);          // obj6: Sum UnitCube box3

// Sharp solids (scene objects)
#declare UnitCube = box { <0, 0, 0>, <1, 1, 1> }
#declare Box1 = box { <0.25, 0.8, 0.25>, <0.75, 1.3, 0.75> }   // y in [0.8,1.3]

// Densities (density trees), all with the one radius Rr
#declare DCube = function { LobbBox(x, y, z, 0,    0,   0,    1,    1,   1,    Rr) }
#declare DBox1 = function { LobbBox(x, y, z, 0.25, 0.8, 0.25, 0.75, 1.3, 0.75, Rr) }
#declare DBox2 = function { LobbBox(x, y, z, 0.25, 0.8, 0.25, 0.75, 1.8, 0.75, Rr) }
#declare DBox3 = function { LobbBox(x, y, z, 0.25, 1.0, 0.25, 0.75, 1.5, 0.75, Rr) }
#declare DObj4 = function { DCube(x, y, z) - DBox1(x, y, z) }   // Difference
#declare DObj6 = function { DCube(x, y, z) + DBox3(x, y, z) }   // Sum

// Containers are outer bounds of the density > 0.5 solid plus a margin M:
//  products of [0,1] densities lie inside the sharp polyhedron (Lobb's
//  Theorem 1); Difference UnitCube box1 lies inside the cube (Theorem 3);
//  Sum UnitCube box3 lies inside the bounding box of the union (outside it
//  only one of the two terms is non-zero, and that term is < 0.5).
// all_intersections is set on the isosurfaces that are operands of a
// difference, where CSG needs more than the first hit (obj3's tool is entered
// above the cube; the hole's walls are its later crossings).

// obj1 = SetDifference UnitCube box1
#macro Obj1() difference { object { UnitCube } object { Box1 } } #end

// obj2 = SetDifference (Rounded r UnitCube) box1
#macro Obj2()
  #ifdef (Tune)
    LobbIso(DCube, <-M, -M, -M>, <1 + M, 1 + M, 1 + M>, MG2, true)
  #else
    difference {
      LobbIso(DCube, <-M, -M, -M>, <1 + M, 1 + M, 1 + M>, MG2, true)
      object { Box1 }
    }
  #end
#end

// obj3 = SetDifference UnitCube (Rounded r box2)
#macro Obj3()
  #ifdef (Tune)
    LobbIso(DBox2, <0.25 - M, 0.8 - M, 0.25 - M>, <0.75 + M, 1.8 + M, 0.75 + M>, MG3, true)
  #else
    difference {
      object { UnitCube }
      LobbIso(DBox2, <0.25 - M, 0.8 - M, 0.25 - M>, <0.75 + M, 1.8 + M, 0.75 + M>, MG3, true)
    }
  #end
#end

// obj4 = Rounded r (Difference UnitCube box1)
#macro Obj4()
  LobbIso(DObj4, <-M, -M, -M>, <1 + M, 1 + M, 1 + M>, MG4, false)
#end

// obj5 = Union (Rounded r UnitCube) (Rounded r box3)
#macro Obj5()
  union {
    LobbIso(DCube, <-M, -M, -M>, <1 + M, 1 + M, 1 + M>, MG5a, false)
    LobbIso(DBox3, <0.25 - M, 1.0 - M, 0.25 - M>, <0.75 + M, 1.5 + M, 0.75 + M>, MG5b, false)
  }
#end

// obj6 = Rounded r (Sum UnitCube box3)
#macro Obj6()
  LobbIso(DObj6, <-M, -M, -M>, <1 + M, 1.5 + M, 1 + M>, MG6, false)
#end

union {
  object { Obj1() translate <0,    0, -1.75> }
  object { Obj2() translate <1.75, 0, -1.75> }
  object { Obj3() translate <3.5,  0, -1.75> }
  object { Obj4() translate <0,    0,  0> }
  object { Obj5() translate <1.75, 0,  0> }
  object { Obj6() translate <3.5,  0,  0> }
  texture { ObjTex }
}
