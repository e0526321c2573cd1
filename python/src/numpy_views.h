#pragma once

// numpy arrays over the host's storage. A view shares the C++ memory (no copy) and keeps
// `owner`, the Python object that owns that memory, alive while the array lives. Views
// and moved-in results are read-only (writeable == False): a write would change the
// model behind the host's checks (a NaN that write() then saves); the bindings give
// explicit setters where a change is meant. Where the storage is not one strided block
// (std::map of points), the bindings make one bulk copy into a new, writable array
// instead, and their docstrings say so.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstddef>
#include <utility>
#include <vector>

namespace tessera::python {

// A view of `shape` with byte `strides` at `data`. An empty shape with null data gives
// an empty array of its own (numpy needs no memory for it).
template <typename T>
pybind11::array_t<T> ReadOnly(pybind11::array_t<T> array) {
  // numpy refuses to make it writeable again: its base is no array (NPY_ARRAY_WRITEABLE
  // can be set back only on arrays that own their data or whose base is writeable).
  pybind11::detail::array_proxy(array.ptr())->flags &=
      ~pybind11::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return array;
}

template <typename T>
pybind11::array_t<T> ArrayView(const T* data, std::vector<pybind11::ssize_t> shape,
                               std::vector<pybind11::ssize_t> strides, pybind11::handle owner) {
  return ReadOnly(pybind11::array_t<T>(std::move(shape), std::move(strides), data, owner));
}

// An array over the data of `container`, which moves to the heap and is freed with the
// array: the host's result becomes numpy's without a copy. `data` gives its first T.
template <typename T, typename Container, typename DataOf>
pybind11::array_t<T> MoveIntoArray(Container container, std::vector<pybind11::ssize_t> shape,
                                   std::vector<pybind11::ssize_t> strides, DataOf data) {
  auto* owned = new Container(std::move(container));
  const pybind11::capsule owner(owned,
                                [](void* pointer) { delete static_cast<Container*>(pointer); });
  return ReadOnly(pybind11::array_t<T>(std::move(shape), std::move(strides), data(*owned), owner));
}

// A new (rows, cols) C-ordered array, for one bulk copy.
template <typename T>
pybind11::array_t<T> NewArray(size_t rows, size_t cols) {
  if (cols == 1) return pybind11::array_t<T>({static_cast<pybind11::ssize_t>(rows)});
  return pybind11::array_t<T>(
      {static_cast<pybind11::ssize_t>(rows), static_cast<pybind11::ssize_t>(cols)});
}

}  // namespace tessera::python
