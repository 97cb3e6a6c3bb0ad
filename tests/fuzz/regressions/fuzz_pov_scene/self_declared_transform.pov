#declare T = transform { transform T }
#declare T = transform { transform T }
camera { location <0,0,-5> look_at 0 transform T }
