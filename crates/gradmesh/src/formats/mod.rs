//! Reading and writing gradient meshes: the native JSON format, the authors' OFF, and OBJ.
