//! A Gmsh `.msh` file of version 2.2: the input is what follows its `$MeshFormat` section
//! (which is fixed, so that the fuzzer spends its time in this version's `$Nodes` and
//! `$Elements`). Whatever the bytes, loading gives a sound mesh or an error naming a line of
//! the file; never a panic.

#![no_main]

use libfuzzer_sys::fuzz_target;

mod check;

fuzz_target!(|data: &[u8]| check::gmsh("2.2 0 8", data));
