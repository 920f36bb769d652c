MeshVersionFormatted 2

Dimension 3

SolAtTetrahedra
6
1 1

0.1
0.2
0.3
0.4
