MeshVersionFormatted 2

Dimension 3

SolAtVertices
7
1 1

0
1
2
3
4
5
6

End
