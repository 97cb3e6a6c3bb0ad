// SPDX-License-Identifier: MIT
// A floor, a wall and a block in sunlight, for povray-ssao's ambient mode (tests/povray): every
// surface has pigment 0.8 and finish ambient 0.2 under ambient_light 1.5, so the ambient term is
// 0.8 x 0.2 x 1.5 = 0.24 everywhere (in the working space), and pixels in the block's shadow show
// nothing else. Declare=Gamma=2.2 renders it with that assumed_gamma.
#version 3.7;
#ifndef (Gamma)
  #declare Gamma = 1.0;
#end
#declare AmbientColour = rgb <1.5, 1.5, 1.5>;
global_settings { assumed_gamma Gamma ambient_light AmbientColour }

camera {
  perspective
  location <0.5, 3.2, -6.5>
  right x * image_width / image_height
  up y
  angle 55
  look_at <0, 0.6, 0>
}
light_source { <6, 9, -4> rgb 1 parallel point_at <0, 0, 0> }
background { rgb <0.5, 0.6, 0.8> }

#declare Matte = texture { pigment { rgb 0.8 } finish { ambient 0.2 diffuse 0.7 } };
plane { y, 0 texture { Matte } }
box { <-5, 0, 1.2>, <5, 2.5, 1.7> texture { Matte } }       // the wall
box { <-1.6, 0, -1.2>, <-0.4, 1.2, 0> texture { Matte } }   // a block on the floor
