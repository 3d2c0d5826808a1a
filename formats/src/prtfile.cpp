// placeholder: replaced by the HDF5 writer/reader
