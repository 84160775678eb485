//! Whether HDF5 can be shut down: it keeps an object whose close failed (its data could not
//! be written: a full disk) although the failed close freed it, and its shutdown, which
//! under MPI runs inside `MPI_Finalize`, closes that object again and crashes (a
//! segmentation fault after the run's own message naming the file and the full disk). A
//! process holding such objects at its end leaves without that shutdown (`main`).

/// How many files, datasets, groups, attributes and named datatypes HDF5 still holds open
/// in this process (none once every file this process wrote was closed, unless a close
/// failed).
pub fn open_objects() -> usize {
    use hdf5_sys::h5f::{
        H5F_OBJ_ALL, H5F_OBJ_ATTR, H5F_OBJ_DATASET, H5F_OBJ_DATATYPE, H5F_OBJ_FILE, H5F_OBJ_GROUP,
    };
    let kinds = H5F_OBJ_DATASET | H5F_OBJ_GROUP | H5F_OBJ_ATTR | H5F_OBJ_DATATYPE | H5F_OBJ_FILE;
    // SAFETY: counts the open objects of every file; reads the library's tables only.
    let n = hdf5::sync::sync(|| unsafe {
        hdf5_sys::h5f::H5Fget_obj_count(H5F_OBJ_ALL as hdf5_sys::h5i::hid_t, kinds)
    });
    n.max(0) as usize
}
