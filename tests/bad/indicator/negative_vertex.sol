MeshVersionFormatted 2

Dimension 3

SolAtVertices
8
1 1

0
1
2
-3
4
5
6
7

End
