#declare C = camera { location <0,0,-5> look_at 0 }
#declare C = camera { C }
camera { C }
