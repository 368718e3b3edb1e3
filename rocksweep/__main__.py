from rocksweep.cli import main

main()
