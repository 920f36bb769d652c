MeshVersionFormatted 2

Dimension 3

SolAtTetrahedra
6
2 1 1

0 0
1 1
2 2
3 3
4 4
5 5

End
