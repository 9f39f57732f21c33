//! A Gmsh `.msh` file of version 4.1: the input is what follows its `$MeshFormat` section
//! (which is fixed, so that the fuzzer spends its time in this version's `$Nodes` and
//! `$Elements`). Whatever the bytes, loading gives a sound mesh or an error naming a line of
//! the file; never a panic.

#![no_main]

use libfuzzer_sys::fuzz_target;

mod check;

fuzz_target!(|data: &[u8]| check::gmsh("4.1 0 8", data));
