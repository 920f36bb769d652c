MeshVersionFormatted 2

Dimension 3

End
