MeshVersionFormatted 2

Dimension 3

SolAtTetrahedra
6
1 2

0.0 0 0
0.1 0 0
0.2 0 0
0.3 0 0
0.4 0 0
0.5 0 0

End
