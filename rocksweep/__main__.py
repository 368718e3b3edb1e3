from rocksweep.cli import entry

entry()
