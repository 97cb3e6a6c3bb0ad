// SPDX-License-Identifier: MIT
// Analytic geometry for the depth-pass test in tests/povray/test_povray.py: a disc of radius 8 in
// the plane y = 0 centred at the origin, and three spheres (centre, radius):
//   <0, 1, 0> 1      bumpy, half mirror
//   <2.2, 0.8, 1.5> 0.8   glass (the depth pass must give its front surface)
//   <-3, 2, 6> 2     plain
// seen by a rotated camera; everything else is the sky. The test traces the same rays with POV-Ray's
// camera model and compares the bridge's Z and Radial channels with the exact distances.
#version 3.7;
global_settings { assumed_gamma 1.0 max_trace_level 8 }

camera {
  location <3, 2.5, -7>
  right x * image_width / image_height
  angle 60
  look_at <0, 1, 2>
}

light_source { <-6, 12, -8> rgb 1 }
background { rgb <0.5, 0.65, 0.9> }

disc { <0, 0, 0>, y, 8
  texture { pigment { checker rgb 0.9 rgb 0.3 } finish { diffuse 0.8 reflection 0.15 } }
}
sphere { <0, 1, 0>, 1
  texture { pigment { rgb <1, 0.8, 0.3> } finish { specular 0.5 reflection 0.5 }
            normal { bumps 0.4 scale 0.15 } }
}
sphere { <2.2, 0.8, 1.5>, 0.8
  texture { pigment { rgbf <0.95, 0.95, 1, 0.95> } finish { specular 0.8 reflection 0.1 } }
  interior { ior 1.5 }
}
sphere { <-3, 2, 6>, 2
  texture { pigment { rgb <0.3, 0.6, 0.4> } finish { diffuse 0.7 } }
}
