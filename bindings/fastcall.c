/* bindings._fastcall: the one-state fast path of Model.accel and Model.step.
 *
 * Through cffi, each NumPy array passed to C costs an ffi.from_buffer (a buffer export and a
 * cdata object), and the output array an np.empty: together about three times the call of
 * the kernel itself.  This module takes the arrays as Python objects instead, reads their data
 * pointers with the NumPy C API and makes the output array in C: one crossing from Python, no
 * Python-level checks.  It decides nothing itself: it calls the binding's sr_py_accel /
 * sr_py_step (bindings/build_sr.py: sr_check_state, then the checked kernel; sr_step checks in full itself), whose addresses
 * cffi hands over.  Anything that is not a float64, C-contiguous, aligned, native-endian array
 * of the exact shape, and any non-zero status of C, returns None: runtime/model.py then takes
 * the full path, which checks in Python's terms and raises the precise message.
 *
 * The GIL is kept during the call (one state: tens to hundreds of ns, less than releasing and
 * taking it back costs).  No mutable globals: the model and the functions live in the object.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/arrayobject.h>

#include <stdint.h>

#include "spherical_robot.h"

typedef int (*accel_fn)(const sr_model *model, const void *x, const void *u, void *a);
typedef int (*step_fn)(const sr_model *model, int method, const void *x, const void *u, double dt, void *x_next);

typedef struct {
    PyObject_HEAD
    const sr_model *model;
    accel_fn accel;
    step_fn step;
    PyObject *owner;        /* keeps the sr_model's memory (a cffi cdata) alive */
} Kernels;

/* The array's data if it is exactly a float64 vector of length n that C can read in place. */
static const double *vector_data(PyObject *obj, npy_intp n)
{
    PyArrayObject *a = (PyArrayObject *)obj;
    if (!PyArray_CheckExact(obj) || PyArray_TYPE(a) != NPY_DOUBLE || PyArray_NDIM(a) != 1
        || PyArray_DIM(a, 0) != n || !PyArray_ISCARRAY_RO(a) || !PyArray_ISNOTSWAPPED(a))
        return NULL;
    return (const double *)PyArray_DATA(a);
}

/* u: None (zero torque, NULL for C) or a float64 vector of SR_NU; *ok = 0 for anything else. */
static const double *input_data(PyObject *u, int *ok)
{
    const double *data;
    *ok = 1;
    if (u == Py_None) return NULL;
    data = vector_data(u, SR_NU);
    if (!data) *ok = 0;
    return data;
}

/* accel(x, u) -> ndarray (5,), or None when the fast path does not apply or C refuses. */
static PyObject *Kernels_accel(Kernels *self, PyObject *const *args, Py_ssize_t nargs)
{
    const double *x, *u;
    npy_intp dims[1] = {SR_NV};
    PyObject *out;
    int ok;
    if (nargs != 2) {
        PyErr_SetString(PyExc_TypeError, "accel(x, u) takes 2 arguments");
        return NULL;
    }
    x = vector_data(args[0], SR_NX);
    u = input_data(args[1], &ok);
    if (!x || !ok) Py_RETURN_NONE;
    out = PyArray_SimpleNew(1, dims, NPY_DOUBLE);
    if (!out) return NULL;
    if (self->accel(self->model, x, u, PyArray_DATA((PyArrayObject *)out)) != SR_OK) {
        Py_DECREF(out);
        Py_RETURN_NONE;
    }
    return out;
}

/* step(x, u, dt, method_code) -> ndarray (35,), or None when the fast path does not apply or C refuses. */
static PyObject *Kernels_step(Kernels *self, PyObject *const *args, Py_ssize_t nargs)
{
    const double *x, *u;
    npy_intp dims[1] = {SR_NX};
    PyObject *out;
    double dt;
    long method;
    int ok;
    if (nargs != 4) {
        PyErr_SetString(PyExc_TypeError, "step(x, u, dt, method) takes 4 arguments");
        return NULL;
    }
    x = vector_data(args[0], SR_NX);
    u = input_data(args[1], &ok);
    /* dt: a Python float or a NumPy float64 (a float subclass) only; anything else, the full path. */
    if (!x || !ok || !PyFloat_Check(args[2]) || !PyLong_CheckExact(args[3])) Py_RETURN_NONE;
    dt = PyFloat_AsDouble(args[2]);
    if (dt == -1.0 && PyErr_Occurred()) return NULL;
    method = PyLong_AsLong(args[3]);
    if (method == -1 && PyErr_Occurred()) return NULL;
    if (method < INT_MIN || method > INT_MAX) Py_RETURN_NONE;
    out = PyArray_SimpleNew(1, dims, NPY_DOUBLE);
    if (!out) return NULL;
    if (self->step(self->model, (int)method, x, u, dt, PyArray_DATA((PyArrayObject *)out)) != SR_OK) {
        Py_DECREF(out);
        Py_RETURN_NONE;
    }
    return out;
}

/* Kernels(model_address, accel_address, step_address, owner): addresses from cffi (runtime/model.py). */
static int Kernels_init(Kernels *self, PyObject *args, PyObject *kwds)
{
    unsigned long long model, accel, step;
    PyObject *owner, *old;
    (void)kwds;
    if (!PyArg_ParseTuple(args, "KKKO", &model, &accel, &step, &owner)) return -1;
    if (!model || !accel || !step) {
        PyErr_SetString(PyExc_ValueError, "Kernels: null address");
        return -1;
    }
    self->model = (const sr_model *)(uintptr_t)model;
    self->accel = (accel_fn)(uintptr_t)accel;
    self->step = (step_fn)(uintptr_t)step;
    old = self->owner;
    Py_INCREF(owner);
    self->owner = owner;
    Py_XDECREF(old);
    return 0;
}

static void Kernels_dealloc(Kernels *self)
{
    Py_XDECREF(self->owner);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

static PyMethodDef Kernels_methods[] = {
    {"accel", (PyCFunction)(void (*)(void))Kernels_accel, METH_FASTCALL,
     "accel(x, u): ndarray (5,), or None (not a plain float64 state / input, or C refused)"},
    {"step", (PyCFunction)(void (*)(void))Kernels_step, METH_FASTCALL,
     "step(x, u, dt, method_code): ndarray (35,), or None (as accel)"},
    {NULL, NULL, 0, NULL},
};

static PyTypeObject KernelsType = {
    PyVarObject_HEAD_INIT(NULL, 0)
    .tp_name = "bindings._fastcall.Kernels",
    .tp_basicsize = sizeof(Kernels),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "The one-state fast path of Model.accel and Model.step (see bindings/fastcall.c).",
    .tp_new = PyType_GenericNew,
    .tp_init = (initproc)Kernels_init,
    .tp_dealloc = (destructor)Kernels_dealloc,
    .tp_methods = Kernels_methods,
};

static struct PyModuleDef fastcall_module = {
    PyModuleDef_HEAD_INIT, "bindings._fastcall",
    "The one-state fast path of Model.accel and Model.step (see bindings/fastcall.c).", -1, NULL,
    NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__fastcall(void)
{
    PyObject *m;
    import_array();
    if (PyType_Ready(&KernelsType) < 0) return NULL;
    m = PyModule_Create(&fastcall_module);
    if (!m) return NULL;
    Py_INCREF(&KernelsType);
    if (PyModule_AddObject(m, "Kernels", (PyObject *)&KernelsType) < 0) {
        Py_DECREF(&KernelsType);
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
